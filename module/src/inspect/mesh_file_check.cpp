#include <meccano/inspect/mesh_file_check.hpp>

#include <meccano/mesh/quality.hpp>
#include <meccano/report/json_writer.hpp>

#include "geometry/compensated_sum.hpp"
#include "mesh/topology_helpers.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace meccano {
namespace {

using Face = std::array<int, 3>;  // vertex indices

CheckResult named(std::string name) {
  CheckResult check;
  check.name = std::move(name);
  return check;
}

class MeshFileChecker {
 public:
  MeshFileChecker(const MshMesh& mesh, int max_reported) : mesh_(mesh), max_reported_(max_reported) {
    lo_ = hi_ = mesh.points.empty() ? Eigen::Vector3d::Zero() : mesh.points[0];
    for (const auto& p : mesh.points) {
      lo_ = lo_.cwiseMin(p);
      hi_ = hi_.cwiseMax(p);
    }
    tolerance_ = 1e-9 * (hi_ - lo_).maxCoeff();
  }

  MeshFileCheck run() {
    MeshFileCheck report{
        mesh_.source, static_cast<std::int64_t>(mesh_.points.size()), static_cast<std::int64_t>(mesh_.tets.size()), {}};
    report.checks.push_back(conformity());
    report.checks.push_back(orientation());
    report.checks.push_back(volume());
    report.checks.push_back(box_sides());
    for (const MshGroup& group : mesh_.groups)
      if (group.dimension == 2 && group.name.starts_with("interface_")) report.checks.push_back(interface(group));
    for (const MshGroup& group : mesh_.groups) {
      if (group.dimension != 3) continue;
      if (group.name.starts_with("inside_")) report.checks.push_back(bounded_region(group, "inside_", true, false));
      if (group.name.starts_with("negative_")) report.checks.push_back(bounded_region(group, "negative_", true, true));
      if (group.name.starts_with("positive_")) report.checks.push_back(bounded_region(group, "positive_", false, true));
    }
    return report;
  }

 private:
  template <class... Parts>
  void problem(CheckResult& check, const Parts&... parts) const {
    check.passed = false;
    if (check.problem_count++ >= max_reported_) return;
    std::ostringstream message;
    message.precision(17);
    (message << ... << parts);
    check.problems.push_back(message.str());
  }
  std::string tet_name(int t) const { return "tet " + std::to_string(mesh_.tet_tags[t]); }
  std::string face_name(const Face& face) const {
    std::ostringstream out;
    out << "face (nodes " << mesh_.point_tags[face[0]] << ", " << mesh_.point_tags[face[1]] << ", "
        << mesh_.point_tags[face[2]] << ")";
    return out.str();
  }
  const Eigen::Vector3d& point(int v) const { return mesh_.points[v]; }
  double tet_volume(int t) const {
    const auto& v = mesh_.tets[t];
    return signed_volume(point(v[0]), point(v[1]), point(v[2]), point(v[3]));
  }
  // The box side (0..5: xmin, xmax, ..., zmax) whose plane holds the whole face, or -1.
  int box_side_of(const Face& face) const {
    for (int side = 0; side < 6; ++side) {
      const int axis = side / 2;
      const double plane = side % 2 ? hi_[axis] : lo_[axis];
      if (std::ranges::all_of(face, [&](int v) { return std::abs(point(v)[axis] - plane) <= tolerance_; })) return side;
    }
    return -1;
  }
  // The run of faces_ with this key: the tets that have the face.
  std::span<const FaceRecord> tets_with(const Face& sorted_key) const {
    const auto [first, last] = std::equal_range(faces_.begin(), faces_.end(), FaceRecord{sorted_key, 0, 0},
                                                [](const FaceRecord& a, const FaceRecord& b) { return a.key < b.key; });
    return {first, last};
  }
  template <class Visit>  // visit(tets sharing one face)
  void for_each_face(Visit&& visit) const {
    for (std::size_t i = 0; i < faces_.size();) {
      std::size_t j = i + 1;
      while (j < faces_.size() && faces_[j].key == faces_[i].key) ++j;
      visit(std::span<const FaceRecord>(faces_.data() + i, j - i));
      i = j;
    }
  }

  CheckResult conformity() const {
    CheckResult check = named("conformity");
    std::int64_t interior = 0, boundary = 0;
    for_each_face([&](std::span<const FaceRecord> sharing) {
      const Face& key = sharing[0].key;
      if (sharing.size() > 2) {
        problem(check, face_name(key), " is shared by ", sharing.size(), " tets (", tet_name(sharing[0].tet), ", ",
                tet_name(sharing[1].tet), ", ", tet_name(sharing[2].tet), sharing.size() > 3 ? ", ..." : "", ")");
      } else if (sharing.size() == 2) {
        ++interior;
        // The opposite vertices of two tets on the two sides of a face are on opposite sides of its plane.
        auto side = [&](const FaceRecord& f) {
          const int apex = mesh_.tets[f.tet][f.local_face];
          return signed_volume(point(key[0]), point(key[1]), point(key[2]), point(apex)) > 0.0;
        };
        if (side(sharing[0]) == side(sharing[1]))
          problem(check, tet_name(sharing[0].tet), " and ", tet_name(sharing[1].tet), " lie on the same side of ",
                  face_name(key), " (they overlap)");
      } else {
        ++boundary;
        if (box_side_of(key) < 0)
          problem(check, face_name(key), " of ", tet_name(sharing[0].tet),
                  " is in no other tet but not on the bounding box (a hole)");
      }
    });
    check.summary = std::to_string(interior) + " interior faces, " + std::to_string(boundary) + " boundary faces";
    return check;
  }

  CheckResult orientation() const {
    CheckResult check = named("orientation");
    std::int64_t negative = 0, flat = 0;
    for (int t = 0; t < static_cast<int>(mesh_.tets.size()); ++t) {
      const double v = tet_volume(t);
      if (v > 0.0) continue;
      ++(v < 0.0 ? negative : flat);
      problem(check, tet_name(t), v < 0.0 ? " is negatively oriented (volume " : " is flat (volume ", v, ")");
    }
    check.summary = std::to_string(negative) + " negative, " + std::to_string(flat) + " flat of " +
                    std::to_string(mesh_.tets.size()) + " tets";
    return check;
  }

  CheckResult volume() const {
    CheckResult check = named("volume");
    CompensatedSum sum;
    for (int t = 0; t < static_cast<int>(mesh_.tets.size()); ++t) sum.add(tet_volume(t));
    const double box = (hi_ - lo_).prod();
    std::ostringstream summary;
    summary.precision(17);
    summary << "tets " << sum.value() << ", bounding box " << box;
    check.summary = summary.str();
    if (!(std::abs(sum.value() - box) <= 1e-9 * box))
      problem(check, "the tets' volume ", sum.value(), " differs from the bounding box volume ", box, " by ",
              sum.value() - box);
    return check;
  }

  CheckResult box_sides() const {
    CheckResult check = named("box sides");
    std::array<const MshGroup*, 6> sides{};
    for (const MshGroup& group : mesh_.groups)
      for (int side = 0; side < 6; ++side)
        if (group.dimension == 2 && group.name == box_side_name(static_cast<BoxSide>(side))) sides[side] = &group;
    if (std::ranges::none_of(sides, [](const MshGroup* g) { return g != nullptr; })) {
      check.summary = "skipped: no 2D groups xmin ... zmax";
      return check;
    }
    std::vector<Face> side_faces;
    for (int side = 0; side < 6; ++side) {
      const char* name = box_side_name(static_cast<BoxSide>(side));
      if (!sides[side]) {
        problem(check, "group ", name, " is missing");
        continue;
      }
      const int axis = side / 2, u = (axis + 1) % 3, w = (axis + 2) % 3;
      CompensatedSum area;
      for (const int e : sides[side]->elements) {
        Face face = mesh_.triangles[e];
        area.add(0.5 * (point(face[1]) - point(face[0])).cross(point(face[2]) - point(face[0])).norm());
        if (box_side_of(face) != side)
          problem(check, name, ": triangle ", mesh_.triangle_tags[e], " does not lie on the plane of ", name);
        std::sort(face.begin(), face.end());
        side_faces.push_back(face);
      }
      const double expected = (hi_[u] - lo_[u]) * (hi_[w] - lo_[w]);
      if (!(std::abs(area.value() - expected) <= tolerance_ * tolerance_ + 1e-9 * expected))
        problem(check, name, ": its triangles' area ", area.value(), " differs from the side's area ", expected);
    }
    // The unshared faces of the tets and the box sides' faces are the same set.
    std::ranges::sort(side_faces);
    std::int64_t boundary = 0;
    for_each_face([&](std::span<const FaceRecord> sharing) {
      if (sharing.size() != 1) return;
      ++boundary;
      if (!std::ranges::binary_search(side_faces, sharing[0].key))
        problem(check, face_name(sharing[0].key), " of ", tet_name(sharing[0].tet),
                " is on the boundary of the mesh but in no box-side group");
    });
    for (const Face& face : side_faces)
      if (tets_with(face).size() != 1) problem(check, face_name(face), " of a box-side group is not a boundary face");
    check.summary =
        std::to_string(side_faces.size()) + " box-side triangles, " + std::to_string(boundary) + " boundary faces";
    return check;
  }

  CheckResult interface(const MshGroup& group) const {
    CheckResult check = named(group.name);
    std::vector<std::array<VertexId, 3>> triangles;
    for (const int e : group.elements) {
      const Face& face = mesh_.triangles[e];
      triangles.push_back(face);
      Face key = face;
      std::sort(key.begin(), key.end());
      if (const auto sharing = tets_with(key).size(); sharing != 2)
        problem(check, "triangle ", mesh_.triangle_tags[e], " is a face of ", sharing, " tets, not an interior face");
    }
    detail::TopologyScratch scratch;
    std::vector<VertexId> vertices;
    const detail::TriangleTopology topology = detail::triangle_topology(triangles, scratch, &vertices);
    const int boundary_loops = detail::count_boundary_loops(scratch);
    // An edge of a consistently oriented surface is run once in each direction.
    std::vector<std::pair<VertexId, VertexId>> directed;
    for (const auto& t : triangles)
      for (int k = 0; k < 3; ++k) directed.push_back({t[k], t[(k + 1) % 3]});
    std::ranges::sort(directed);
    std::int64_t flipped = 0;
    for (std::size_t i = 1; i < directed.size(); ++i) flipped += directed[i] == directed[i - 1];

    // An open interface is a disk, a closed one (no boundary edge) a sphere.
    const bool closed = !triangles.empty() && topology.boundary_edges == 0;
    const char* kind = closed ? "a closed interface" : "a disk";
    if (triangles.empty()) problem(check, "the group has no triangles");
    if (topology.components > 1) problem(check, topology.components, " connected components (", kind, " has one)");
    if (topology.overloaded_edges > 0) problem(check, topology.overloaded_edges, " edges in more than two triangles");
    if (topology.pinched_vertices > 0) problem(check, topology.pinched_vertices, " pinched vertices");
    if (topology.euler() != (closed ? 2 : 1))
      problem(check, "Euler characteristic ", topology.euler(), " (", kind, " has ", closed ? 2 : 1, ")");
    if (!closed && boundary_loops != 1) problem(check, boundary_loops, " boundary loops (a disk has one)");
    if (flipped > 0) problem(check, flipped, " edges run twice in the same direction (inconsistent orientation)");
    // Not a defect of the mesh, but a fault solver that splits the interface's nodes needs a node off the
    // interface in every tet: counted, not failed (a coarse mesh that keeps the surface may have some).
    const auto on_interface = [&](int node) { return std::ranges::binary_search(vertices, node); };
    const auto lying_on = std::ranges::count_if(
        mesh_.tets, [&](const std::array<int, 4>& tet) { return std::ranges::all_of(tet, on_interface); });
    check.summary = std::to_string(triangles.size()) + " triangles, Euler characteristic " +
                    std::to_string(topology.euler()) + ", " + std::to_string(boundary_loops) + " boundary loop(s)";
    if (lying_on > 0) check.summary += ", " + std::to_string(lying_on) + " tets with all four nodes on it";
    return check;
  }

  // A region bounded by interface_NAME: inside_NAME, the tets a closed interface encloses, or
  // negative_NAME and positive_NAME, the two parts of the box a clipped interface divides it into. Across
  // each interface face the group has one tet, whose outward normal is the face's (`normals_out`: out of
  // an inclusion, out of the negative side) or its opposite (into the positive side); every other face
  // between a tet of the group and one outside it is an interface face; only with `reaches_box` may a
  // tet of it lie on the box.
  CheckResult bounded_region(const MshGroup& group, const std::string& prefix, bool normals_out,
                             bool reaches_box) const {
    CheckResult check = named(group.name);
    const std::string interface_name = "interface_" + group.name.substr(prefix.size());
    const auto interface = std::ranges::find_if(
        mesh_.groups, [&](const MshGroup& g) { return g.dimension == 2 && g.name == interface_name; });
    if (interface == mesh_.groups.end()) {
      problem(check, "no 2D group ", interface_name, " bounds it");
      return check;
    }
    std::vector<std::uint8_t> member(mesh_.tets.size(), 0);
    for (const int t : group.elements) member[t] = 1;
    std::vector<Face> bounding;
    for (const int e : interface->elements) {
      const Face& face = mesh_.triangles[e];
      Face key = face;
      std::ranges::sort(key);
      bounding.push_back(key);
      const auto sharing = tets_with(key);
      const auto inner = std::ranges::find_if(sharing, [&](const FaceRecord& r) { return member[r.tet] != 0; });
      if (sharing.size() != 2 ||
          std::ranges::count_if(sharing, [&](const FaceRecord& r) { return member[r.tet]; }) != 1) {
        problem(check, "triangle ", mesh_.triangle_tags[e], " of ", interface_name,
                " does not have one tet of the group behind it");
        continue;
      }
      // The tet's vertex off the face lies behind the face's normal.
      const auto& tet = mesh_.tets[inner->tet];
      const int apex = *std::ranges::find_if(tet, [&](int v) { return std::ranges::find(face, v) == face.end(); });
      const Eigen::Vector3d& a = mesh_.points[face[0]];
      const Eigen::Vector3d normal = (mesh_.points[face[1]] - a).cross(mesh_.points[face[2]] - a);
      const double behind = normal.dot(mesh_.points[apex] - a);
      if (!(normals_out ? behind < 0.0 : behind > 0.0))
        problem(check, "triangle ", mesh_.triangle_tags[e], " of ", interface_name,
                normals_out ? " points into " : " points out of ", tet_name(inner->tet));
    }
    std::ranges::sort(bounding);
    CompensatedSum volume;
    for (const int t : group.elements) volume.add(tet_volume(t));
    for_each_face([&](std::span<const FaceRecord> sharing) {
      const auto members = std::ranges::count_if(sharing, [&](const FaceRecord& r) { return member[r.tet]; });
      if (sharing.size() == 1 && members == 1 && !reaches_box)
        problem(check, tet_name(sharing[0].tet), " is on the box boundary");
      else if (sharing.size() == 2 && members == 1 && !std::ranges::binary_search(bounding, sharing[0].key))
        problem(check, face_name(sharing[0].key), " between ", tet_name(sharing[0].tet), " and ",
                tet_name(sharing[1].tet), " leaves the group without crossing ", interface_name);
    });
    std::ostringstream summary;
    summary << group.elements.size() << " tets, volume " << volume.value() << ", bounded by " << interface_name;
    check.summary = summary.str();
    return check;
  }

  const MshMesh& mesh_;
  int max_reported_;
  Eigen::Vector3d lo_, hi_;
  double tolerance_ = 0.0;
  std::vector<FaceRecord> faces_ = sorted_face_records(mesh_.tets);  // every local face of every tet, sorted by key
};

}  // namespace

bool MeshFileCheck::passed() const {
  return std::ranges::all_of(checks, [](const CheckResult& c) { return c.passed; });
}

const CheckResult* MeshFileCheck::find(const std::string& name) const {
  const auto found = std::ranges::find(checks, name, &CheckResult::name);
  return found == checks.end() ? nullptr : &*found;
}

std::string MeshFileCheck::text() const {
  std::ostringstream out;
  out << source << ": " << nodes << " nodes, " << tets << " tets\n";
  for (const CheckResult& c : checks) {
    out << c.name << ": " << (c.passed ? "ok" : "FAILED") << " (" << c.summary << ")\n";
    for (const std::string& p : c.problems) out << "  " << p << '\n';
    if (c.problem_count > static_cast<std::int64_t>(c.problems.size()))
      out << "  ... and " << c.problem_count - static_cast<std::int64_t>(c.problems.size()) << " more\n";
  }
  out << (passed() ? "passed" : "FAILED") << '\n';
  return out.str();
}

std::string MeshFileCheck::json() const {
  JsonWriter json;
  json.begin_object().key("file").value(source).key("nodes").value(nodes).key("tets").value(tets);
  json.key("passed").value(passed()).key("checks").begin_array();
  for (const CheckResult& c : checks) {
    json.begin_object().key("name").value(c.name).key("passed").value(c.passed).key("summary").value(c.summary);
    json.key("problem_count").value(c.problem_count).key("problems").begin_array();
    for (const std::string& p : c.problems) json.value(p);
    json.end_array().end_object();
  }
  json.end_array().end_object();
  return json.str();
}

MeshFileCheck check_msh_mesh(const MshMesh& mesh, int max_reported) {
  return MeshFileChecker(mesh, max_reported).run();
}

MeshFileCheck check_mesh_file(const std::string& path, int max_reported) {
  return check_msh_mesh(read_msh_mesh(path), max_reported);
}

}  // namespace meccano
