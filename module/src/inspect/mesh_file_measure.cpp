#include <meccano/inspect/mesh_file_measure.hpp>

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/report/json_writer.hpp>
#include <meccano/surface/box_clipping.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

namespace meccano {
namespace {

constexpr int samples_per_edge = 8;  // see the header: 45 samples per triangle

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

double triangle_area(const Triangle3& t) { return 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm(); }

Triangle3 corners(const TriangleSurface& surface, int t) {
  const auto& v = surface.triangles[t];
  return {surface.points[v[0]], surface.points[v[1]], surface.points[v[2]]};
}

// Millions of terms: summed in extended precision so that the mean does not depend on their order
// beyond the last bits.
double mean_of(const std::vector<double>& values) {
  long double sum = 0;
  for (const double v : values) sum += v;
  return values.empty() ? 0.0 : static_cast<double>(sum / static_cast<long double>(values.size()));
}

double area_of(const TriangleSurface& surface) {
  long double sum = 0;
  for (int t = 0; t < static_cast<int>(surface.triangles.size()); ++t) sum += triangle_area(corners(surface, t));
  return static_cast<double>(sum);
}

void measure_quality(const MshMesh& mesh, MeshMeasure& measure) {
  const auto tets = static_cast<std::int64_t>(mesh.tets.size());
  const QualitySummary summary = summarize_tet_quality(tets, [&](std::int64_t t, QualityAccumulator& quality) {
    const auto& v = mesh.tets[t];
    quality.add({mesh.points[v[0]], mesh.points[v[1]], mesh.points[v[2]], mesh.points[v[3]]});
  });
  measure.inverted = summary.inverted;
  measure.equilateral = summary.equilateral;
  measure.below = summary.equilateral_below;
  measure.min_dihedral_deg = summary.min_dihedral_deg;
  measure.max_dihedral_deg = summary.max_dihedral_deg;
}

// The group's triangles as a surface of their own, its nodes renumbered, the file's vertex order kept.
TriangleSurface group_surface(const MshMesh& mesh, const MshGroup& group) {
  TriangleSurface surface;
  surface.name = group.name;
  surface.source = mesh.source;
  std::vector<int> nodes;
  for (const int e : group.elements) nodes.insert(nodes.end(), mesh.triangles[e].begin(), mesh.triangles[e].end());
  std::ranges::sort(nodes);
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  for (const int v : nodes) surface.points.push_back(mesh.points[v]);
  for (const int e : group.elements) {
    auto& triangle = surface.triangles.emplace_back();
    for (int k = 0; k < 3; ++k)
      triangle[k] = static_cast<int>(std::ranges::lower_bound(nodes, mesh.triangles[e][k]) - nodes.begin());
  }
  return surface;
}

// max over the samples of `from`'s triangles of their distance to `to` (one side of the Hausdorff distance).
double sampled_distance(const TriangleBVH& from, const TriangleBVH& to) {
  double largest2 = 0.0;
#pragma omp parallel for schedule(dynamic, 64) reduction(max : largest2)
  for (int t = 0; t < from.triangle_count(); ++t) {
    const Triangle3& c = from.triangle(t);
    for (int i = 0; i <= samples_per_edge; ++i)
      for (int j = 0; i + j <= samples_per_edge; ++j) {
        // Multiples of a power of two over it: the corners are sampled exactly.
        const Eigen::Vector3d x = (i * c[0] + j * c[1] + (samples_per_edge - i - j) * c[2]) / samples_per_edge;
        largest2 = std::max(largest2, to.closest_point(x).squared_distance);
      }
  }
  return std::sqrt(largest2);
}


bool is_interface(const MshGroup& group) { return group.dimension == 2 && group.name.starts_with("interface_"); }

std::string surface_label(const TriangleSurface& surface) {
  return "surface " + surface.name + (surface.source.empty() ? "" : " (" + surface.source + ")");
}

// The surface each interface group is compared with, by group; InputError for a surface that matches no
// group or the group of another surface.
std::vector<const TriangleSurface*> match_surfaces(const MshMesh& mesh, std::span<const TriangleSurface> surfaces) {
  std::vector<const TriangleSurface*> matched(mesh.groups.size(), nullptr);
  std::string interface_names;
  for (const MshGroup& group : mesh.groups)
    if (is_interface(group)) interface_names += (interface_names.empty() ? "" : ", ") + group.name;
  for (const TriangleSurface& surface : surfaces) {
    const std::string name = "interface_" + surface.name;
    const auto group =
        std::ranges::find_if(mesh.groups, [&](const MshGroup& g) { return is_interface(g) && g.name == name; });
    if (group == mesh.groups.end())
      throw InputError(surface_label(surface) + ": " + mesh.source + " has no 2D group " + name +
                       " (its interface groups: " + (interface_names.empty() ? "none" : interface_names) + ")");
    const TriangleSurface*& slot = matched[group - mesh.groups.begin()];
    if (slot)
      throw InputError(surface_label(surface) + " and " + surface_label(*slot) + " are both named " + surface.name);
    if (surface.triangles.empty()) throw InputError(surface_label(surface) + " has no triangles");
    if (group->elements.empty())
      throw InputError(mesh.source + ": group " + name + " has no triangles to compare with " + surface_label(surface));
    slot = &surface;
  }
  return matched;
}

}  // namespace

SurfaceAccuracy accuracy_against(const TriangleSurface& interface, const TriangleSurface& surface) {
  const TriangleBVH on_surface(surface), on_interface(interface);
  SurfaceAccuracy accuracy;
  accuracy.surface = surface.source;

  std::vector<double> node_distance(interface.points.size());
#pragma omp parallel for
  for (std::size_t v = 0; v < node_distance.size(); ++v)
    node_distance[v] = std::sqrt(on_surface.closest_point(interface.points[v]).squared_distance);
  accuracy.node_distance_max = *std::ranges::max_element(node_distance);
  accuracy.node_distance_mean = mean_of(node_distance);

  accuracy.hausdorff = std::max(sampled_distance(on_interface, on_surface), sampled_distance(on_surface, on_interface));

  const int faces = on_interface.triangle_count();
  std::vector<double> angle(faces), area(faces);
  std::vector<char> flipped(faces);
#pragma omp parallel for
  for (int f = 0; f < faces; ++f) {
    const Triangle3& c = on_interface.triangle(f);
    const Eigen::Vector3d normal = (c[1] - c[0]).cross(c[2] - c[0]).normalized();
    const Triangle3& s = on_surface.triangle(on_surface.closest_point((c[0] + c[1] + c[2]) / 3.0).triangle);
    const Eigen::Vector3d surface_normal = (s[1] - s[0]).cross(s[2] - s[0]).normalized();
    const double cosine = normal.dot(surface_normal);
    flipped[f] = cosine < 0.0;
    // atan2 rather than acos: exact to rounding for the nearly parallel normals of a good interface.
    angle[f] = degrees(std::atan2(normal.cross(surface_normal).norm(), std::abs(cosine)));
    area[f] = triangle_area(c);
  }
  long double weighted = 0, total = 0;
  for (int f = 0; f < faces; ++f) {
    weighted += angle[f] * area[f];
    total += area[f];
    accuracy.flipped_faces += flipped[f];
  }
  accuracy.normal_deviation_max_deg = *std::ranges::max_element(angle);
  accuracy.normal_deviation_mean_deg = total > 0 ? static_cast<double>(weighted / total) : 0.0;
  accuracy.area_ratio = static_cast<double>(total) / area_of(surface);
  return accuracy;
}

const InterfaceMeasure* MeshMeasure::find(const std::string& name) const {
  const auto found = std::ranges::find(interfaces, name, &InterfaceMeasure::name);
  return found == interfaces.end() ? nullptr : &*found;
}

std::string MeshMeasure::text() const {
  std::ostringstream out;
  out.precision(6);
  out << source << ": " << nodes << " nodes, " << tets << " tets, " << inverted << " inverted\n"
      << "quality: equilateral mean ratio min " << equilateral.min << ", mean " << equilateral.mean << ", std "
      << equilateral.std;
  for (std::size_t k = 0; k < below.size(); ++k)
    out << (k ? ", " : "; below ") << low_quality_thresholds[k] << ": " << below[k];
  out << "; dihedral angles " << min_dihedral_deg << " to " << max_dihedral_deg << " deg\n";
  for (const InterfaceMeasure& i : interfaces) {
    out << i.name << ": " << i.faces << " faces, area " << i.area << '\n';
    if (!i.accuracy) continue;
    const SurfaceAccuracy& a = *i.accuracy;
    out << "  against " << a.surface << ": node distance max " << a.node_distance_max << ", mean "
        << a.node_distance_mean << "; Hausdorff " << a.hausdorff << "; normal deviation max "
        << a.normal_deviation_max_deg << ", mean " << a.normal_deviation_mean_deg << " deg; " << a.flipped_faces
        << " flipped faces; area ratio " << a.area_ratio << '\n';
  }
  return out.str();
}

std::string MeshMeasure::json() const {
  JsonWriter json;
  json.begin_object().key("file").value(source).key("nodes").value(nodes).key("tets").value(tets);
  json.key("inverted").value(inverted).key("quality").begin_object().key("equilateral").begin_object();
  json.key("min").value(equilateral.min).key("mean").value(equilateral.mean).key("std").value(equilateral.std);
  for (std::size_t k = 0; k < below.size(); ++k) json.key(low_quality_keys[k]).value(below[k]);
  json.end_object().key("min_dihedral_deg").value(min_dihedral_deg).key("max_dihedral_deg").value(max_dihedral_deg);
  json.end_object().key("interfaces").begin_array();
  for (const InterfaceMeasure& i : interfaces) {
    json.begin_object().key("name").value(i.name).key("faces").value(i.faces).key("area").value(i.area);
    if (i.accuracy) {
      const SurfaceAccuracy& a = *i.accuracy;
      json.key("surface").value(a.surface);
      json.key("node_distance").begin_object();
      json.key("max").value(a.node_distance_max);
      json.key("mean").value(a.node_distance_mean);
      json.end_object();
      json.key("hausdorff").value(a.hausdorff);
      json.key("normal_deviation_deg").begin_object().key("max").value(a.normal_deviation_max_deg);
      json.key("mean").value(a.normal_deviation_mean_deg).end_object();
      json.key("flipped_faces").value(a.flipped_faces).key("area_ratio").value(a.area_ratio);
    }
    json.end_object();
  }
  json.end_array().end_object();
  return json.str();
}

MeshMeasure measure_msh_mesh(const MshMesh& mesh, std::span<const TriangleSurface> surfaces) {
  // A surface reaching beyond the mesh's box is compared by its part inside, as inserted
  // (surface/box_clipping.hpp: several parts are NAME_1, NAME_2, ...).
  Box box{Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()),
          Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity())};
  for (const Eigen::Vector3d& p : mesh.points) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  }
  std::vector<TriangleSurface> inside;
  for (const TriangleSurface& surface : surfaces) {
    std::vector<TriangleSurface> parts =
        mesh.points.empty() ? std::vector<TriangleSurface>{surface} : clip_to_box(surface, box);
    inside.insert(inside.end(), parts.begin(), parts.end());
  }
  const std::vector<const TriangleSurface*> matched = match_surfaces(mesh, inside);
  MeshMeasure measure;
  measure.source = mesh.source;
  measure.nodes = static_cast<std::int64_t>(mesh.points.size());
  measure.tets = static_cast<std::int64_t>(mesh.tets.size());
  measure_quality(mesh, measure);
  for (std::size_t g = 0; g < mesh.groups.size(); ++g) {
    const MshGroup& group = mesh.groups[g];
    if (!is_interface(group)) continue;
    const TriangleSurface interface = group_surface(mesh, group);
    InterfaceMeasure& i = measure.interfaces.emplace_back();
    i.name = group.name;
    i.faces = static_cast<std::int64_t>(interface.triangles.size());
    i.area = area_of(interface);
    if (matched[g]) i.accuracy = accuracy_against(interface, *matched[g]);
  }
  return measure;
}

MeshMeasure measure_mesh_file(const std::string& path, std::span<const TriangleSurface> surfaces) {
  return measure_msh_mesh(read_msh_mesh(path), surfaces);
}

}  // namespace meccano
