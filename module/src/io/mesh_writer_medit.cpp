// Medit .mesh ASCII (MeshVersionFormatted 2: double precision), references from the groups.
#include <meccano/io/mesh_writers.hpp>

#include "io/writer_helpers.hpp"

#include <meccano/io/atomic_file.hpp>

namespace meccano {

void write_medit(const TetMesh& mesh, const MeshGroups& groups, const std::string& path) {
  mesh_io::check_groups(mesh, groups);
  // A tet's reference is its first 3D group; 0 = in none, not written.
  std::vector<int> reference(mesh.tets.size(), 0);
  for (auto group = groups.volumes.rbegin(); group != groups.volumes.rend(); ++group)
    for (const TetId t : group->tets) reference[t] = group->tag;
  std::int64_t tets = 0;
  for (const int ref : reference) tets += ref != 0;

  write_file_atomically(path, [&](std::ostream& stream) {
    mesh_io::TextWriter out(stream);
    // Readers take the first line for the version, so the comments come after the header.
    out << "MeshVersionFormatted 2\nDimension 3\n";
    for (const TetGroup& group : groups.volumes)
      out << "# Tetrahedra ref " << group.tag << ' ' << std::string_view(group.name) << '\n';
    for (const FaceGroup& group : groups.surfaces)
      out << "# Triangles ref " << group.tag << ' ' << std::string_view(group.name) << '\n';

    out << "Vertices\n" << mesh.num_vertices() << '\n';
    for (const auto& p : mesh.points) out << p.x() << ' ' << p.y() << ' ' << p.z() << " 0\n";

    out << "Tetrahedra\n" << tets << '\n';
    for (TetId t = 0; t < mesh.num_tets(); ++t) {
      if (reference[t] == 0) continue;
      const auto v = mesh.oriented_tet(t);
      out << v[0] + 1 << ' ' << v[1] + 1 << ' ' << v[2] + 1 << ' ' << v[3] + 1 << ' ' << reference[t] << '\n';
    }

    out << "Triangles\n" << mesh_io::group_triangle_count(groups) << '\n';
    mesh_io::for_each_group_triangle(mesh, groups, [&](int tag, const auto& face) {
      out << face[0] + 1 << ' ' << face[1] + 1 << ' ' << face[2] + 1 << ' ' << tag << '\n';
    });
    out << "End\n";
  });
}

}  // namespace meccano
