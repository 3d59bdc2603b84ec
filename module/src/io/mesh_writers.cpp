#include <meccano/io/mesh_writers.hpp>

#include "io/writer_helpers.hpp"

#include <meccano/error.hpp>

#include <array>
#include <map>
#include <set>
#include <stdexcept>
#include <string_view>
#include <utility>

namespace meccano {
namespace mesh_io {

namespace {

// `what` names the kind of thing named: "mesh group", "node field".
void check_name(const std::string& name, const char* what) {
  if (name.empty()) throw std::invalid_argument(std::string(what) + ": empty name");
  for (const char c : name)
    if (c == '"' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      throw std::invalid_argument(std::string(what) + " '" + name + "': names may not hold '\"' or control characters");
}

}  // namespace

void check_node_fields(const TetMesh& mesh, std::span<const NodeField> node_fields) {
  for (const NodeField& field : node_fields) {
    check_name(field.name, "node field");
    if (field.values.size() != mesh.points.size())
      throw std::invalid_argument("node field " + field.name + ": " + std::to_string(field.values.size()) +
                                  " values for " + std::to_string(mesh.points.size()) + " nodes");
  }
}

void check_groups(const TetMesh& mesh, const MeshGroups& groups) {
  auto check_tet = [&](const std::string& name, TetId t) {
    if (t < 0 || t >= mesh.num_tets())
      throw std::invalid_argument("mesh group " + name + ": tet " + std::to_string(t) + " does not exist (" +
                                  std::to_string(mesh.num_tets()) + " tets)");
  };
  auto check_tags = [](const auto& same_dimension, const char* dimension) {
    std::set<int> tags;
    for (const auto& group : same_dimension) {
      if (group.tag < 1)
        throw std::invalid_argument("mesh group " + group.name + ": tag " + std::to_string(group.tag) +
                                    " is not positive");
      if (!tags.insert(group.tag).second)
        throw std::invalid_argument("mesh group " + group.name + ": tag " + std::to_string(group.tag) +
                                    " is already the tag of another " + dimension + " group");
    }
  };
  check_tags(groups.volumes, "3D");
  check_tags(groups.surfaces, "2D");
  for (const TetGroup& group : groups.volumes) {
    check_name(group.name, "mesh group");
    for (const TetId t : group.tets) check_tet(group.name, t);
  }
  for (const FaceGroup& group : groups.surfaces) {
    check_name(group.name, "mesh group");
    for (const FaceRef& face : group.faces) {
      check_tet(group.name, face.tet);
      if (face.local_face < 0 || face.local_face > 3)
        throw std::invalid_argument("mesh group " + group.name + ": tet " + std::to_string(face.tet) +
                                    " has no local face " + std::to_string(face.local_face));
    }
  }
}

std::int64_t group_tet_count(const MeshGroups& groups) {
  std::int64_t count = 0;
  for (const TetGroup& group : groups.volumes) count += static_cast<std::int64_t>(group.tets.size());
  return count;
}

std::int64_t group_triangle_count(const MeshGroups& groups) {
  std::int64_t count = 0;
  for (const FaceGroup& group : groups.surfaces) count += static_cast<std::int64_t>(group.faces.size());
  return count;
}

}  // namespace mesh_io

MeshGroups standard_groups(const TetMesh& mesh, const std::vector<std::string>& interface_names) {
  MeshGroups groups;
  TetGroup domain{"domain", domain_tag, {}};
  domain.tets.resize(mesh.tets.size());
  for (TetId t = 0; t < mesh.num_tets(); ++t) domain.tets[t] = t;
  groups.volumes.push_back(std::move(domain));

  std::vector<FaceGroup> sides(6);
  for (int s = 0; s < 6; ++s) {
    sides[s].name = box_side_name(static_cast<BoxSide>(s));
    sides[s].tag = box_side_tag(static_cast<BoxSide>(s));
  }
  std::map<int, FaceGroup> interfaces;
  for (TetId t = 0; t < mesh.num_tets(); ++t)
    for (int f = 0; f < 4; ++f) {
      const FaceTag tag = mesh.face_tags[t][f];
      if (is_box_side_tag(tag)) {
        sides[tag - 1].faces.push_back({t, f});
      } else if (is_interface_tag(tag)) {
        const TetId other = mesh.neighbours[t][f];
        if (other != no_tet && other < t) continue;  // written once, from the first tet
        const int index = interface_index(tag);
        auto& group = interfaces[index];
        group.name = "interface_" + (index < static_cast<int>(interface_names.size()) ? interface_names[index]
                                                                                      : std::to_string(index + 1));
        group.tag = tag;
        group.faces.push_back({t, f});
      }
    }
  for (auto& side : sides) groups.surfaces.push_back(std::move(side));
  for (auto& [index, group] : interfaces) groups.surfaces.push_back(std::move(group));
  return groups;
}

namespace {

constexpr std::array<std::pair<std::string_view, MeshFormat>, 3> format_extensions{
    {{".msh", MeshFormat::msh}, {".vtu", MeshFormat::vtu}, {".mesh", MeshFormat::medit}}};

}  // namespace

std::optional<MeshFormat> mesh_format_of(const std::string& path) {
  for (const auto& [extension, format] : format_extensions)
    if (path.size() > extension.size() && path.ends_with(extension)) return format;
  return std::nullopt;
}

void write_mesh(const TetMesh& mesh, const MeshGroups& groups, const std::string& path, const MeshWriteOptions& options,
                std::span<const NodeField> node_fields) {
  const std::optional<MeshFormat> format = mesh_format_of(path);
  if (!format)
    throw InputError("cannot write " + path + ": unknown mesh format (the extensions are .msh, .vtu and .mesh)");
  switch (*format) {
    case MeshFormat::msh:
      if (options.msh_version == MshVersion::v22) write_msh22(mesh, groups, path, node_fields);
      else write_msh41(mesh, groups, path, node_fields);
      return;
    case MeshFormat::vtu: write_vtu(mesh, groups, path, node_fields); return;
    case MeshFormat::medit:
      if (!node_fields.empty())
        throw InputError("cannot write " + path + ": a Medit file holds no node data (node field " +
                         node_fields.front().name + "); write .msh or .vtu");
      write_medit(mesh, groups, path);
      return;
  }
}

}  // namespace meccano
