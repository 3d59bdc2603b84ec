// Medit .mesh ASCII (MeshVersionFormatted 2: double precision), references from the groups.
#include <meccano/mesh_io.hpp>

#include "mesh_io_helpers.hpp"

#include <meccano/atomic_file.hpp>

namespace meccano {

void write_medit(const TetMesh& mesh, const MeshGroups& groups, const std::string& path) {
  mesh_io::check_groups(mesh, groups);
  // A tet's reference is its first 3D group; 0 = in none, not written.
  std::vector<int> reference(mesh.tets.size(), 0);
  for (std::size_t g = groups.volumes.size(); g-- > 0;)
    for (const TetId t : groups.volumes[g].tets) reference[t] = static_cast<int>(g + 1);
  std::int64_t tets = 0;
  for (const int ref : reference) tets += ref != 0;

  write_file_atomically(path, [&](std::ostream& stream) {
    mesh_io::TextWriter out(stream);
    // Readers take the first line for the version, so the comments come after the header.
    out << "MeshVersionFormatted 2\nDimension 3\n";
    for (std::size_t g = 0; g < groups.volumes.size(); ++g)
      out << "# Tetrahedra ref " << static_cast<int>(g + 1) << ' ' << std::string_view(groups.volumes[g].name) << '\n';
    for (std::size_t g = 0; g < groups.surfaces.size(); ++g)
      out << "# Triangles ref " << static_cast<int>(g + 1) << ' ' << std::string_view(groups.surfaces[g].name) << '\n';

    out << "Vertices\n" << mesh.num_vertices() << '\n';
    for (const auto& p : mesh.points) out << p.x() << ' ' << p.y() << ' ' << p.z() << " 0\n";

    out << "Tetrahedra\n" << tets << '\n';
    for (TetId t = 0; t < mesh.num_tets(); ++t) {
      if (reference[t] == 0) continue;
      const auto v = mesh.oriented_tet(t);
      out << v[0] + 1 << ' ' << v[1] + 1 << ' ' << v[2] + 1 << ' ' << v[3] + 1 << ' ' << reference[t] << '\n';
    }

    out << "Triangles\n" << mesh_io::group_triangle_count(groups) << '\n';
    mesh_io::for_each_group_triangle(mesh, groups, [&](int group, const auto& face) {
      out << face[0] + 1 << ' ' << face[1] + 1 << ' ' << face[2] + 1 << ' ' << group + 1 << '\n';
    });
    out << "End\n";
  });
}

}  // namespace meccano
