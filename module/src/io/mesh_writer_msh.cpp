// Gmsh MSH 4.1 and 2.2 ASCII.
#include <meccano/io/mesh_writers.hpp>

#include "io/writer_helpers.hpp"

#include <meccano/error.hpp>
#include <meccano/io/atomic_file.hpp>

#include <algorithm>
#include <map>

namespace meccano {
namespace {

using mesh_io::TextWriter;

// Partition of items (tets, or faces keyed tet·4 + f) into entities by the set of groups each belongs
// to; an entity holds the items of one membership set, in increasing key order.
struct Partition {
  std::vector<std::vector<int>> entity_groups;
  std::vector<std::vector<std::int64_t>> entity_items;
};

Partition partition_by_membership(std::int64_t key_count, const std::vector<std::vector<std::int64_t>>& group_keys) {
  if (group_keys.size() > 64) throw InputError("more than 64 groups of one dimension cannot be written");
  std::vector<std::uint64_t> membership(static_cast<std::size_t>(key_count), 0);
  for (std::size_t g = 0; g < group_keys.size(); ++g)
    for (std::int64_t key : group_keys[g]) membership[key] |= std::uint64_t{1} << g;
  Partition partition;
  std::map<std::uint64_t, std::size_t> entity_of_mask;
  for (std::int64_t key = 0; key < key_count; ++key) {
    const std::uint64_t mask = membership[key];
    if (mask == 0) continue;
    auto [it, inserted] = entity_of_mask.try_emplace(mask, partition.entity_groups.size());
    if (inserted) {
      std::vector<int> groups;
      for (int g = 0; g < 64; ++g)
        if (mask >> g & 1) groups.push_back(g);
      partition.entity_groups.push_back(std::move(groups));
      partition.entity_items.emplace_back();
    }
    partition.entity_items[it->second].push_back(key);
  }
  // Entities in the order of their groups, so that files are stable and easy to read.
  std::vector<std::size_t> order(partition.entity_groups.size());
  for (std::size_t e = 0; e < order.size(); ++e) order[e] = e;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return partition.entity_groups[a] < partition.entity_groups[b]; });
  Partition sorted;
  for (std::size_t e : order) {
    sorted.entity_groups.push_back(std::move(partition.entity_groups[e]));
    sorted.entity_items.push_back(std::move(partition.entity_items[e]));
  }
  return sorted;
}

// The same in both versions: the groups' own tags.
void write_physical_names(TextWriter& out, const MeshGroups& groups) {
  out << "$PhysicalNames\n" << static_cast<int>(groups.volumes.size() + groups.surfaces.size()) << '\n';
  for (const TetGroup& group : groups.volumes)
    out << "3 " << group.tag << " \"" << std::string_view(group.name) << "\"\n";
  for (const FaceGroup& group : groups.surfaces)
    out << "2 " << group.tag << " \"" << std::string_view(group.name) << "\"\n";
  out << "$EndPhysicalNames\n";
}

void write_point(TextWriter& out, const Eigen::Vector3d& p) { out << p.x() << ' ' << p.y() << ' ' << p.z() << '\n'; }

// The same in both versions: a $NodeData section per field, at time 0 and step 0, nodes tagged v + 1.
void write_node_data(TextWriter& out, std::span<const NodeField> node_fields) {
  for (const NodeField& field : node_fields) {
    const auto nodes = static_cast<std::int64_t>(field.values.size());
    out << "$NodeData\n1\n\"" << std::string_view(field.name) << "\"\n1\n0\n3\n0\n1\n" << nodes << '\n';
    for (std::int64_t v = 0; v < nodes; ++v)
      out << v + 1 << ' ' << mesh_io::written_value(field, field.values[v], 1) << '\n';
    out << "$EndNodeData\n";
  }
}

}  // namespace

void write_msh41(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
                 std::span<const NodeField> node_fields) {
  mesh_io::check_groups(mesh, groups);
  mesh_io::check_node_fields(mesh, node_fields);
  std::vector<std::vector<std::int64_t>> tet_keys, face_keys;
  for (const auto& g : groups.volumes) tet_keys.emplace_back(g.tets.begin(), g.tets.end());
  for (const auto& g : groups.surfaces) {
    auto& keys = face_keys.emplace_back();
    for (const FaceRef& f : g.faces) keys.push_back(std::int64_t{f.tet} * 4 + f.local_face);
  }
  const Partition volumes = partition_by_membership(mesh.num_tets(), tet_keys);
  const Partition surfaces = partition_by_membership(std::int64_t{4} * mesh.num_tets(), face_keys);

  write_file_atomically(path, [&](std::ostream& stream) {
    TextWriter out(stream);
    out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
    write_physical_names(out, groups);

    const Box& box = mesh.meccano.box;
    auto bounding_box = [&] {
      out << box.min.x() << ' ' << box.min.y() << ' ' << box.min.z() << ' ' << box.max.x() << ' ' << box.max.y() << ' '
          << box.max.z();
    };
    auto physical_tags = [&](const std::vector<int>& member_of, const auto& same_dimension) {
      out << ' ' << static_cast<int>(member_of.size());
      for (int g : member_of) out << ' ' << same_dimension[g].tag;
    };
    out << "$Entities\n0 0 " << static_cast<int>(surfaces.entity_groups.size()) << ' '
        << static_cast<int>(volumes.entity_groups.size()) << '\n';
    for (std::size_t e = 0; e < surfaces.entity_groups.size(); ++e) {
      out << static_cast<int>(e + 1) << ' ';
      bounding_box();
      physical_tags(surfaces.entity_groups[e], groups.surfaces);
      out << " 0\n";
    }
    for (std::size_t e = 0; e < volumes.entity_groups.size(); ++e) {
      out << static_cast<int>(e + 1) << ' ';
      bounding_box();
      physical_tags(volumes.entity_groups[e], groups.volumes);
      out << " 0\n";
    }
    out << "$EndEntities\n";

    // All nodes in one block of the first volume entity; MSH 4.1 allows elements of any entity to use them.
    const std::int64_t nodes = mesh.num_vertices();
    out << "$Nodes\n1 " << nodes << " 1 " << nodes << "\n3 1 0 " << nodes << '\n';
    for (std::int64_t v = 1; v <= nodes; ++v) out << v << '\n';
    for (const auto& p : mesh.points) write_point(out, p);
    out << "$EndNodes\n";

    std::int64_t element_count = 0;
    for (const auto& items : surfaces.entity_items) element_count += static_cast<std::int64_t>(items.size());
    for (const auto& items : volumes.entity_items) element_count += static_cast<std::int64_t>(items.size());
    out << "$Elements\n"
        << static_cast<int>(surfaces.entity_items.size() + volumes.entity_items.size()) << ' ' << element_count << " 1 "
        << element_count << '\n';
    std::int64_t tag = 0;
    for (std::size_t e = 0; e < surfaces.entity_items.size(); ++e) {
      out << "2 " << static_cast<int>(e + 1) << " 2 " << static_cast<std::int64_t>(surfaces.entity_items[e].size())
          << '\n';
      for (std::int64_t key : surfaces.entity_items[e]) {
        const auto face = mesh.outward_face(static_cast<TetId>(key / 4), static_cast<int>(key % 4));
        out << ++tag << ' ' << face[0] + 1 << ' ' << face[1] + 1 << ' ' << face[2] + 1 << '\n';
      }
    }
    for (std::size_t e = 0; e < volumes.entity_items.size(); ++e) {
      out << "3 " << static_cast<int>(e + 1) << " 4 " << static_cast<std::int64_t>(volumes.entity_items[e].size())
          << '\n';
      for (std::int64_t t : volumes.entity_items[e]) {
        const auto v = mesh.oriented_tet(static_cast<TetId>(t));
        out << ++tag << ' ' << v[0] + 1 << ' ' << v[1] + 1 << ' ' << v[2] + 1 << ' ' << v[3] + 1 << '\n';
      }
    }
    out << "$EndElements\n";
    write_node_data(out, node_fields);
  });
}

void write_msh22(const TetMesh& mesh, const MeshGroups& groups, const std::string& path,
                 std::span<const NodeField> node_fields) {
  mesh_io::check_groups(mesh, groups);
  mesh_io::check_node_fields(mesh, node_fields);
  write_file_atomically(path, [&](std::ostream& stream) {
    TextWriter out(stream);
    out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
    write_physical_names(out, groups);

    out << "$Nodes\n" << mesh.num_vertices() << '\n';
    for (VertexId v = 0; v < mesh.num_vertices(); ++v) {
      out << v + 1 << ' ';
      write_point(out, mesh.points[v]);
    }
    out << "$EndNodes\n";

    // Element lines: number, type (2 triangle, 4 tet), 2 tags (physical, elementary), nodes. The
    // elementary entity of a group's copy of an element is the group's own, so that no entity holds an
    // element twice.
    std::int64_t number = 0;
    auto element = [&](int type, int tag, const auto& vertices) {
      out << ++number << ' ' << type << " 2 " << tag << ' ' << tag;
      for (const VertexId v : vertices) out << ' ' << v + 1;
      out << '\n';
    };
    out << "$Elements\n" << mesh_io::group_triangle_count(groups) + mesh_io::group_tet_count(groups) << '\n';
    mesh_io::for_each_group_triangle(mesh, groups, [&](int tag, const auto& face) { element(2, tag, face); });
    mesh_io::for_each_group_tet(mesh, groups, [&](int tag, TetId, const auto& tet) { element(4, tag, tet); });
    out << "$EndElements\n";
    write_node_data(out, node_fields);
  });
}

}  // namespace meccano
