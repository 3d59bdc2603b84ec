// The MSH volume-mesh reader (io/msh_reader.hpp): the tets and triangles that io/msh_parser.hpp reads,
// an element that MSH 2.2 writes once per group merged into one, and the groups built from them.
#include <meccano/io/msh_reader.hpp>

#include <meccano/error.hpp>

#include "io/byte_cursor.hpp"
#include "io/msh_parser.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <utility>

namespace meccano {
namespace {

constexpr int kTriangle = 2;  // Gmsh element types
constexpr int kTet = 4;

using Members = std::map<std::pair<int, int>, std::vector<int>>;  // (dimension, physical tag) -> elements

// Adds the elements of `type` (N vertices, `dimension`) to `elements` and `tags`, and to the groups in
// `members`. A record with the vertices of an earlier element that is in none of its groups is that
// element written again for another group: merged. Repeated in a group it is in (or with no group), it
// stays a separate element, for the checks to report.
template <std::size_t N>
void add_elements(const readers::MshFile& file, int type, int dimension, std::vector<std::array<int, N>>& elements,
                  std::vector<std::uint64_t>& tags, Members& members) {
  const auto found = file.elements.find(type);
  if (found == file.elements.end()) return;
  const readers::MshElements& records = found->second;
  std::map<std::array<int, N>, std::pair<int, std::vector<int>>> seen;  // sorted vertices -> element, its groups
  for (std::size_t r = 0; r < records.tags.size(); ++r) {
    std::array<int, N> vertices;
    std::copy_n(records.vertices.begin() + static_cast<std::ptrdiff_t>(N * r), N, vertices.begin());
    std::array<int, N> key = vertices;
    std::ranges::sort(key);
    const std::vector<int>& physical = file.physical_sets[static_cast<std::size_t>(records.physical[r])];
    auto [slot, added] = seen.try_emplace(key);
    auto& [index, groups] = slot->second;
    const auto& known_groups = groups;  // clang 14 cannot capture a structured binding
    const bool merged = !added && !physical.empty() && std::ranges::none_of(physical, [&known_groups](int g) {
      return std::ranges::count(known_groups, g) > 0;
    });
    if (!merged) {
      index = static_cast<int>(elements.size());
      elements.push_back(vertices);
      tags.push_back(records.tags[r]);
      groups.clear();
    }
    for (const int g : physical) {
      groups.push_back(g);
      members[{dimension, g}].push_back(index);
    }
  }
}

}  // namespace

MshMesh read_msh_mesh(const std::string& path) {
  constexpr std::array<int, 2> kKept{kTriangle, kTet};
  readers::MshFile file = readers::parse_msh_file(path, readers::read_file_bytes(path), kKept);
  MshMesh mesh;
  mesh.source = path;
  Members members;
  add_elements(file, kTet, 3, mesh.tets, mesh.tet_tags, members);
  add_elements(file, kTriangle, 2, mesh.triangles, mesh.triangle_tags, members);
  if (mesh.tets.empty()) throw InputError(path + ": no tets (element type 4) in the file");
  for (auto& [key, list] : members) {
    std::ranges::sort(list);
    list.erase(std::unique(list.begin(), list.end()), list.end());
    const auto name = file.physical_names.find(key);
    mesh.groups.push_back(
        {key.first, key.second, name == file.physical_names.end() ? "" : name->second, std::move(list)});
  }
  mesh.points = std::move(file.points);
  mesh.point_tags = std::move(file.point_tags);
  return mesh;
}

}  // namespace meccano
