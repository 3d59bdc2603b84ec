// reference-gmsh: the reference mesh that meccano-immerse is compared with. Gmsh (C++ API) re-meshes the
// whole box with the surfaces embedded as constraints, keeping every input triangle as it is, and writes
// the same physical groups as meccano-immerse, so that both outputs go through the same readers and the
// same quality code (meccano/mesh/quality.hpp).
//
// Recipe ("keep", shared/notes/peers.md §2.2): each surface becomes a discrete Gmsh surface;
// classifySurfaces creates its rim curve without reparametrizing it, so Gmsh never remeshes it; the box
// is a built-in (geo) volume built *after* the classification, which clears built-in entities; the
// surfaces are embedded in the volume. With --size-near-surface, a mesh size growing with the distance to
// the surfaces (Gmsh's Threshold law) grades the tets from that size at the surfaces to --size, as
// meccano-immerse's grade towards l_r.
// Exit status: 0 success, 1 failure (bad input data, meshing failed, cannot write), 2 usage error.

#include "reference_common.hpp"

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/mesh/tet_mesh.hpp>
#include <meccano/surface/closed_surface.hpp>

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace {

constexpr const char* usage_text =
    R"(Usage: reference-gmsh --box XMIN YMIN ZMIN XMAX YMAX ZMAX --surface FILE[:NAME] [--surface ...]
                      --size H --output FILE.msh [options]

Builds the reference tetrahedral mesh that meccano-immerse is compared with: Gmsh 3D meshes the box
with the surfaces embedded, keeping every surface triangle as it is, and writes the groups that
meccano-immerse writes.

Options:
  --box XMIN YMIN ZMIN XMAX YMAX ZMAX  the box (required); the comma form of meccano-immerse,
                           --box X0,Y0,Z0,X1,Y1,Z1, is accepted too
  --surface FILE[:NAME]    a triangulated surface strictly inside the box, open or closed (a closed
                           one bounds a volume of its own, the 3D group inside_NAME) (.obj, .stl,
                           .off, .msh); NAME defaults to its 1-based position (may repeat; at least one)
  --size H                 mesh size on the box (required); near a surface the tets follow the size
                           of its triangles, which Gmsh cannot split: below 0.7 x their mean edge
                           length it leaves nearly flat tets against them (a warning says so)
  --size-near-surface H0   a graded mesh: size H0 at the surfaces, growing linearly with the distance
                           to them up to H at --size-distance (Gmsh's Threshold law on the distance
                           to the surfaces' triangles); 0 < H0 <= H. Give the surfaces triangles of
                           about H0 (they are kept, so the same limit of 0.7 applies to H0). Gmsh
                           follows the size loosely, HXT more loosely than Delaunay
  --size-distance D        the distance from the surfaces at which the size reaches H (D > 0; only
                           with --size-near-surface, and required by it)
  --output FILE.msh        Gmsh MSH 4.1 ASCII with the 3D group `domain`, the 2D groups xmin, xmax,
                           ymin, ymax, zmin, zmax and interface_NAME per surface (required)
  --algorithm hxt|delaunay Gmsh's 3D algorithm: HXT (Mesh.Algorithm3D = 10, default) or Delaunay (1);
                           both followed by Gmsh's default tet optimizer (Mesh.Optimize = 1)
  --threads N              threads for Gmsh (General.NumThreads; default 1; HXT uses them)
  --report FILE.json       counts, timings, the size field (size_near_surface and size_distance, null
                           without one) and quality: equilateral mean ratio min/mean/std and
                           min/max dihedral angle, computed by meccano's own quality functions
  --quiet                  no progress output and no Gmsh messages
  --help                   this text

Example:
  reference-gmsh --box 0 0 0 1 1 1 --surface meshes/cube_example.obj:patch --size 0.05 \
                 --output reference.msh --report reference.json
)";

using meccano::reference::UsageError;

enum class Algorithm { hxt, delaunay };

// Size near_surface at the surfaces, growing linearly to --size at `distance` from them.
struct SizeField {
  double near_surface = 0.0;
  double distance = 0.0;
};

struct Options {
  meccano::reference::CommonOptions common;
  Algorithm algorithm = Algorithm::hxt;
  int threads = 1;
  std::optional<SizeField> size_field;
};

double parse_positive(const std::string& option, const std::string& text) {
  const double number = meccano::tools::parse_finite_number(option, text);
  if (!(number > 0)) throw UsageError(option + " must be positive");
  return number;
}

Options parse_options(int argc, char** argv) {
  Options options;
  std::optional<double> size_near_surface, size_distance;
  meccano::reference::parse_arguments(argc, argv, usage_text, options.common,
                                      [&](meccano::tools::ArgumentParser& parser) {
    parser.value({"--algorithm"}, [&](const std::string& text) {
      options.algorithm = meccano::tools::parse_choice<Algorithm>(
          "--algorithm", text, {{"hxt", Algorithm::hxt}, {"delaunay", Algorithm::delaunay}},
          "the algorithms available are: hxt, delaunay");
    });
    parser.value({"--threads"}, [&](const std::string& text) {
      const double threads = meccano::tools::parse_finite_number("--threads", text);
      if (threads != std::floor(threads) || threads < 1 || threads > 1024)
        throw UsageError("--threads takes an integer between 1 and 1024");
      options.threads = static_cast<int>(threads);
    });
    parser.value({"--size-near-surface"},
                 [&](const std::string& text) { size_near_surface = parse_positive("--size-near-surface", text); });
    parser.value({"--size-distance"},
                 [&](const std::string& text) { size_distance = parse_positive("--size-distance", text); });
  });
  if (size_near_surface.has_value() != size_distance.has_value())
    throw UsageError("--size-near-surface and --size-distance go together: give both or neither");
  if (size_near_surface) {
    if (*size_near_surface > *options.common.size)
      throw UsageError("--size-near-surface must not exceed --size (the size far from the surfaces)");
    options.size_field = SizeField{*size_near_surface, *size_distance};
  }
  return options;
}

// Gmsh keeps global state: one model per process, finalized on every way out.
class GmshSession {
 public:
  GmshSession() { gmsh::initialize(0, nullptr, /*readConfigFiles=*/false); }
  ~GmshSession() { gmsh::finalize(); }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
};

// Adds every surface as a discrete surface and returns, per surface, the tag of the discrete surface
// that holds its triangles after classifySurfaces (which renumbers the entities but keeps node tags).
std::vector<int> add_surfaces(const std::vector<meccano::TriangleSurface>& surfaces) {
  std::vector<std::size_t> first_node_tag;
  std::size_t next_node_tag = 1;
  for (const auto& surface : surfaces) {
    const int entity = gmsh::model::addDiscreteEntity(2);
    first_node_tag.push_back(next_node_tag);
    std::vector<std::size_t> node_tags;
    std::vector<double> coordinates;
    for (const auto& p : surface.points) {
      node_tags.push_back(next_node_tag++);
      coordinates.insert(coordinates.end(), {p.x(), p.y(), p.z()});
    }
    std::vector<std::size_t> triangle_nodes;
    for (const auto& triangle : surface.triangles)
      for (int corner : triangle) triangle_nodes.push_back(first_node_tag.back() + static_cast<std::size_t>(corner));
    gmsh::model::mesh::addNodes(2, entity, node_tags, coordinates);
    gmsh::model::mesh::addElementsByType(entity, 2, {}, triangle_nodes);
  }
  // Angle pi: no surface is split at a crease; boundary curves for the rims; no reparametrization, so
  // Gmsh keeps the triangles.
  gmsh::model::mesh::classifySurfaces(std::numbers::pi, true, false, std::numbers::pi);

  std::vector<int> entity_of_surface(surfaces.size(), -1);
  gmsh::vectorpair entities;
  gmsh::model::getEntities(entities, 2);
  for (const auto& [dim, tag] : entities) {
    std::vector<std::size_t> element_tags, node_tags;
    gmsh::model::mesh::getElementsByType(2, element_tags, node_tags, tag);
    if (node_tags.empty()) continue;
    const auto s = static_cast<std::size_t>(
        std::upper_bound(first_node_tag.begin(), first_node_tag.end(), node_tags.front()) - first_node_tag.begin() - 1);
    if (entity_of_surface[s] != -1 || element_tags.size() != surfaces[s].triangles.size())
      throw meccano::MeshingError("Gmsh split surface " + surfaces[s].name + " into several pieces");
    entity_of_surface[s] = tag;
  }
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    if (entity_of_surface[s] == -1) throw meccano::MeshingError("Gmsh lost surface " + surfaces[s].name);
  return entity_of_surface;
}

struct BoxEntities {
  int volume = -1;
  std::array<int, 6> sides{};  // in meccano::BoxSide order
};

// The box in Gmsh's built-in kernel, every point with mesh size h. Corner c has coordinate k at the
// maximum when bit k of c is set; sides are numbered 2k + (0 at the minimum, 1 at the maximum), which is
// meccano::BoxSide's order. `holes` are surface loops (closed surfaces) the box volume leaves out.
BoxEntities add_box(const meccano::Box& box, double h, const std::vector<int>& holes) {
  std::array<int, 8> corner_tags{};
  for (int c = 0; c < 8; ++c) {
    const auto coordinate = [&](int k) { return (c >> k & 1) ? box.max[k] : box.min[k]; };
    corner_tags[c] = gmsh::model::geo::addPoint(coordinate(0), coordinate(1), coordinate(2), h);
  }
  std::map<std::pair<int, int>, int> line_of_edge;  // (from corner, to corner) with from < to
  for (int c = 0; c < 8; ++c)
    for (int k = 0; k < 3; ++k)
      if (!(c >> k & 1))
        line_of_edge[{c, c | 1 << k}] = gmsh::model::geo::addLine(corner_tags[c], corner_tags[c | 1 << k]);
  const auto oriented_line = [&](int from, int to) {
    return from < to ? line_of_edge.at({from, to}) : -line_of_edge.at({to, from});
  };
  BoxEntities entities;
  for (int k = 0; k < 3; ++k)
    for (int at_max = 0; at_max < 2; ++at_max) {
      // Counter-clockwise around +k seen from outside at the maximum; reversed at the minimum, so that
      // every side's normal points out of the box.
      const int a = (k + 1) % 3, b = (k + 2) % 3, base = at_max << k;
      std::array<int, 4> quad{base, base | 1 << a, base | 1 << a | 1 << b, base | 1 << b};
      if (!at_max) std::reverse(quad.begin(), quad.end());
      const int loop =
          gmsh::model::geo::addCurveLoop({oriented_line(quad[0], quad[1]), oriented_line(quad[1], quad[2]),
                                          oriented_line(quad[2], quad[3]), oriented_line(quad[3], quad[0])});
      entities.sides[2 * k + at_max] = gmsh::model::geo::addPlaneSurface({loop});
    }
  std::vector<int> loops{gmsh::model::geo::addSurfaceLoop({entities.sides.begin(), entities.sides.end()})};
  loops.insert(loops.end(), holes.begin(), holes.end());
  entities.volume = gmsh::model::geo::addVolume(loops);
  return entities;
}

// The background mesh size of --size-near-surface: Gmsh's Threshold law on the exact distance to the
// surfaces' triangles. Gmsh 4.8.4's own Distance field cannot serve: on a discrete surface it samples no
// point (a Distance + Threshold field on the kept surface left the mesh unchanged, measured), so the
// distance is meccano's, through Gmsh's mesh size callback. Gmsh takes the smallest of this size and
// those of the geometry (box corners at --size, the kept triangles), so the triangles still set the
// size on S itself.
void set_size_field(const std::vector<meccano::TriangleSurface>& surfaces, const SizeField& field, double size) {
  auto trees = std::make_shared<std::vector<meccano::TriangleBVH>>(surfaces.begin(), surfaces.end());
  gmsh::model::mesh::setSizeCallback([trees, field, size](int, int, double x, double y, double z) {
    double distance = std::numeric_limits<double>::infinity();
    for (const auto& tree : *trees)
      distance = std::min(distance, std::sqrt(tree.closest_point({x, y, z}).squared_distance));
    return std::min(size, field.near_surface + (size - field.near_surface) * distance / field.distance);
  });
}

// With its tag given: left to itself, Gmsh numbers physical groups across dimensions (domain 1, the
// sides 2-7), not as meccano-immerse does.
void add_named_group(int dim, const std::vector<int>& entities, int tag, const std::string& name) {
  gmsh::model::addPhysicalGroup(dim, entities, tag);
  gmsh::model::setPhysicalName(dim, tag, name);
}

// Counts and quality of the tets Gmsh made, measured like every reference's (reference_common.hpp).
// Gmsh 4.8.4's HXT leaves holes next to the inside of a closed surface on some meshes (tets missing,
// their neighbours' faces unshared inside the box), and with several threads it cracks some meshes
// around an embedded surface: two nodes at one point, the tets on either side each using one of them.
// Such a mesh is no reference, and is refused, saying which of the two it is.
void require_no_holes(const std::vector<std::size_t>& tet_nodes, const std::vector<Eigen::Vector3d>& point_of_tag,
                      const meccano::Box& box) {
  std::vector<std::array<meccano::VertexId, 4>> tets(tet_nodes.size() / 4);
  for (std::size_t t = 0; t < tets.size(); ++t)
    for (int i = 0; i < 4; ++i) tets[t][i] = static_cast<meccano::VertexId>(tet_nodes[4 * t + i]);
  const auto faces = meccano::sorted_face_records(tets);
  const double tolerance = 1e-9 * box.extent().maxCoeff();
  const auto on_box_side = [&](const std::array<meccano::VertexId, 3>& face) {
    for (int axis = 0; axis < 3; ++axis)
      for (double plane : {box.min[axis], box.max[axis]})
        if (std::ranges::all_of(face, [&](meccano::VertexId v) {
              return std::abs(point_of_tag[static_cast<std::size_t>(v)][axis] - plane) <= tolerance;
            }))
          return true;
    return false;
  };
  std::vector<meccano::VertexId> hole_nodes;
  std::size_t holes = 0;
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const bool shared =
        (i + 1 < faces.size() && faces[i + 1].key == faces[i].key) || (i > 0 && faces[i - 1].key == faces[i].key);
    if (shared || on_box_side(faces[i].key)) continue;
    ++holes;
    hole_nodes.insert(hole_nodes.end(), faces[i].key.begin(), faces[i].key.end());
  }
  if (holes == 0) return;
  // Nodes of the tets by position: a hole's node that shares its point with another node is a crack.
  std::map<std::array<double, 3>, int> nodes_at;
  std::vector<char> counted(point_of_tag.size(), 0);
  for (std::size_t tag : tet_nodes)
    if (!std::exchange(counted[tag], 1)) {
      const Eigen::Vector3d& p = point_of_tag[tag];
      ++nodes_at[{p.x(), p.y(), p.z()}];
    }
  std::sort(hole_nodes.begin(), hole_nodes.end());
  hole_nodes.erase(std::unique(hole_nodes.begin(), hole_nodes.end()), hole_nodes.end());
  const auto coincident = std::ranges::count_if(hole_nodes, [&](meccano::VertexId v) {
    const Eigen::Vector3d& p = point_of_tag[static_cast<std::size_t>(v)];
    return nodes_at.at({p.x(), p.y(), p.z()}) > 1;
  });
  throw meccano::MeshingError(
      "Gmsh left holes in the mesh: " + std::to_string(holes) + " tet faces inside the box belong to one tet only" +
      (coincident > 0 ? "; " + std::to_string(coincident) + " of their " + std::to_string(hole_nodes.size()) +
                            " nodes share their point with another node (cracks, as HXT makes with several "
                            "threads on some meshes: --threads 1 may mesh it)"
                      : " (--algorithm delaunay may mesh it)"));
}

meccano::reference::MeshSummary summarize_mesh(const meccano::Box& box) {
  std::vector<std::size_t> node_tags;
  std::vector<double> coordinates, parametric;
  gmsh::model::mesh::getNodes(node_tags, coordinates, parametric);
  const std::size_t max_tag = node_tags.empty() ? 0 : *std::max_element(node_tags.begin(), node_tags.end());
  std::vector<Eigen::Vector3d> point_of_tag(max_tag + 1);
  for (std::size_t i = 0; i < node_tags.size(); ++i)
    point_of_tag[node_tags[i]] = {coordinates[3 * i], coordinates[3 * i + 1], coordinates[3 * i + 2]};

  std::vector<std::size_t> tet_tags, tet_nodes;
  gmsh::model::mesh::getElementsByType(4, tet_tags, tet_nodes);
  if (tet_tags.empty()) throw meccano::MeshingError("Gmsh produced no tetrahedra");
  require_no_holes(tet_nodes, point_of_tag, box);
  return meccano::reference::summarize_tets(tet_tags.size(), node_tags.size(), [&](std::size_t t) {
    meccano::TetPoints p;
    for (int i = 0; i < 4; ++i) p[i] = point_of_tag[tet_nodes[4 * t + i]];
    return p;
  });
}

// gmsh::write, its errors (thrown as strings) as InputError naming the file.
void write_gmsh_msh(const std::string& path) {
  try {
    gmsh::write(path);
  } catch (const std::string& gmsh_error) {
    throw meccano::InputError("cannot write " + path + ": " + gmsh_error);
  }
}

// Key names follow meccano::QualitySummary, so that the reference tools' reports read alike.
void write_report(const meccano::reference::ReferenceRun& run, const Options& options, double total_seconds,
                  const std::string& path) {
  std::string version;
  gmsh::option::getString("General.Version", version);
  meccano::reference::write_report(
      run,
      [&](meccano::JsonWriter& json) {
    json.key("gmsh_version").value(version);
    json.key("algorithm").value(options.algorithm == Algorithm::hxt ? "hxt" : "delaunay");
    json.key("threads").value(options.threads);
    if (options.size_field) {
      json.key("size_near_surface").value(options.size_field->near_surface);
      json.key("size_distance").value(options.size_field->distance);
    } else {
      json.key("size_near_surface").null();
      json.key("size_distance").null();
    }
      },
      total_seconds, path);
}

// Gmsh cannot split the kept triangles, and when the tets around them must be much smaller HXT leaves
// nearly flat tets against them (measured on the cube example's patch on a 24 x 24 grid: size / mean
// edge 0.71 gives eta_min 0.42, 0.61 gives eta_min 0.003 and dihedral angles of 0.01 and 180 degrees;
// the 48 x 48 grid of meshes/cube_example.obj at size / mean edge 0.42: eta_min 0.001).
constexpr double finest_size_for_kept_triangles = 0.7;

double mean_edge_length(const meccano::TriangleSurface& surface) {
  double sum = 0.0;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) sum += (surface.points[t[(k + 1) % 3]] - surface.points[t[k]]).norm();
  return sum / (3.0 * static_cast<double>(surface.triangles.size()));
}

int run(const Options& options) {
  using meccano::reference::Clock;
  const meccano::reference::CommonOptions& common = options.common;
  const auto [start, progress, surfaces] = meccano::reference::start_run(common);
  const char* size_option = options.size_field ? "--size-near-surface" : "--size";
  const double size_at_surfaces = options.size_field ? options.size_field->near_surface : *common.size;
  for (const auto& surface : surfaces)
    if (const double edge = mean_edge_length(surface); size_at_surfaces < finest_size_for_kept_triangles * edge)
      progress.say("warning: ", size_option, " ", size_at_surfaces, " is below ", finest_size_for_kept_triangles,
                   " x the mean edge length ", edge, " of surface ", surface.name,
                   ": next to its kept triangles Gmsh leaves nearly flat tets");

  const GmshSession session;
  gmsh::option::setNumber("General.Terminal", common.quiet ? 0 : 1);
  gmsh::option::setNumber("General.Verbosity", 2);  // errors and warnings; progress is ours
  gmsh::option::setNumber("General.NumThreads", options.threads);
  gmsh::option::setNumber("Mesh.MeshSizeMax", *common.size);
  gmsh::option::setNumber("Mesh.Algorithm3D", options.algorithm == Algorithm::hxt ? 10 : 1);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::option::setNumber("Mesh.Binary", 0);

  gmsh::model::add("reference");
  const std::vector<int> surface_entities = add_surfaces(surfaces);
  // An open surface is embedded in the box volume. A closed one bounds a volume of its own, its inside,
  // which the box volume leaves out (Gmsh leaves the inside of an embedded closed surface empty).
  std::vector<int> inside_volumes(surfaces.size(), -1), holes, embedded;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    if (!meccano::is_closed(surfaces[s])) {
      embedded.push_back(surface_entities[s]);
      continue;
    }
    holes.push_back(gmsh::model::geo::addSurfaceLoop({surface_entities[s]}));
    inside_volumes[s] = gmsh::model::geo::addVolume({holes.back()});
  }
  const BoxEntities box = add_box(common.box, *common.size, holes);
  gmsh::model::geo::synchronize();
  if (!embedded.empty()) gmsh::model::mesh::embed(2, embedded, 3, box.volume);
  if (options.size_field) set_size_field(surfaces, *options.size_field, *common.size);

  std::vector<int> volumes{box.volume};
  for (int inside : inside_volumes)
    if (inside >= 0) volumes.push_back(inside);
  add_named_group(3, volumes, meccano::domain_tag, "domain");
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    if (inside_volumes[s] >= 0)
      add_named_group(3, {inside_volumes[s]}, meccano::domain_tag + 1 + static_cast<int>(s),
                      "inside_" + surfaces[s].name);
  for (int side = 0; side < 6; ++side) {
    const auto box_side = static_cast<meccano::BoxSide>(side);
    add_named_group(2, {box.sides[side]}, meccano::box_side_tag(box_side), meccano::box_side_name(box_side));
  }
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    add_named_group(2, {surface_entities[s]}, meccano::interface_tag(static_cast<int>(s)),
                    "interface_" + surfaces[s].name);

  if (options.size_field)
    progress.say("gmsh: size field: ", options.size_field->near_surface, " at the surfaces, growing to ", *common.size,
                 " at distance ", options.size_field->distance);
  progress.say("gmsh: meshing with ", options.algorithm == Algorithm::hxt ? "HXT" : "Delaunay", ", size ", *common.size,
               ", ", options.threads, " thread(s)");
  const auto meshing_start = Clock::now();
  gmsh::model::mesh::generate(3);
  const double meshing_seconds = meccano::reference::seconds_since(meshing_start);

  // The reference promises S as given: 3D boundary recovery must not have split any input triangle.
  std::vector<std::pair<std::string, std::size_t>> interface_triangles;
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    std::vector<std::size_t> element_tags, node_tags;
    gmsh::model::mesh::getElementsByType(2, element_tags, node_tags, surface_entities[s]);
    if (element_tags.size() != surfaces[s].triangles.size())
      throw meccano::MeshingError("Gmsh changed the triangles of surface " + surfaces[s].name + " (" +
                                  std::to_string(surfaces[s].triangles.size()) + " given, " +
                                  std::to_string(element_tags.size()) + " meshed)");
    interface_triangles.emplace_back(surfaces[s].name, element_tags.size());
  }
  const meccano::reference::ReferenceRun record{"reference-gmsh", *common.size, std::move(interface_triangles),
                                                summarize_mesh(common.box), meshing_seconds};
  progress.say("gmsh: ", meccano::reference::describe(record.mesh), " in ", record.meshing_seconds, " s");

  meccano::reference::write_outputs(common, progress, write_gmsh_msh, [&](const std::string& path) {
    write_report(record, options, meccano::reference::seconds_since(start), path);
  });
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return meccano::tools::run_reporting_errors("reference-gmsh", [&] {
    try {
      return run(parse_options(argc, argv));
    } catch (const std::string& gmsh_error) {  // the Gmsh 4.8 API throws its error messages as strings
      throw meccano::MeshingError("gmsh: " + gmsh_error);
    }
  });
}
