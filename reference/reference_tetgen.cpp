// reference-tetgen: the TetGen reference mesh that meccano-immerse is compared with. TetGen 1.5
// (libtet) re-meshes the whole box as a piecewise linear complex: the six box sides are quad facets with
// markers 1..6 (meccano::BoxSide order, = meccano's face tags), every triangle of surface k (1-based) a
// facet with marker 6 + k. Constrained Delaunay refinement (-q, -a) splits the surface triangles with
// Steiner points but, with -M (no merging of nearly coplanar facets), keeps every output face inside an
// input triangle, so the interface is the input surface itself; -Y (--keep-surface) forbids the splits.
// The output has the groups meccano-immerse writes, in MSH 4.1 ASCII written here: meccano's MSH writer
// takes a meccano TetMesh, and libgmsh cannot write it because libgmsh and libtet define the same TetGen
// symbols (this executable must not link libgmsh).
//
// TetGen's conventions, measured on the cube example at --size 0.1 (318 792 tets, 33 910 interface
// faces): its tets are positively oriented; its box faces point into the box, so they are flipped here;
// its interface faces keep the input triangles' orientation, which is enforced here anyway, against the
// nearest input triangle, since TetGen's documentation does not promise it. Its -nn face adjacency is
// not used: outside some box faces it gives tet 0 instead of -1.
// Exit status: 0 success, 1 failure (bad input data, meshing failed, cannot write), 2 usage error.

#include "reference_common.hpp"

#include <meccano/error.hpp>
#include <meccano/geometry/geometry.hpp>
#include <meccano/io/atomic_file.hpp>
#include <meccano/mesh/tet_mesh.hpp>

// Declares tetrahedralize(char* switches, ...); Debian's libtet is built with it, so every TetGen
// failure is a `throw int` (terminatetetgen in tetgen.h).
#define TETLIBRARY
#include <tetgen.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <initializer_list>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace {

constexpr const char* usage_text =
    R"(Usage: reference-tetgen --box XMIN YMIN ZMIN XMAX YMAX ZMAX --surface FILE[:NAME] [--surface ...]
                        --size H --output FILE.msh [options]

Builds a reference tetrahedral mesh for meccano-immerse: TetGen 1.5 meshes the box with the surfaces as
internal facets (constrained Delaunay refinement) and writes the groups that meccano-immerse writes.
Without --keep-surface TetGen splits the surface triangles, but every interface face lies in an input
triangle: the interface is the input surface itself.

Options:
  --box XMIN YMIN ZMIN XMAX YMAX ZMAX  the box (required); the comma form of meccano-immerse,
                           --box X0,Y0,Z0,X1,Y1,Z1, is accepted too
  --surface FILE[:NAME]    a triangulated surface strictly inside the box, open or closed (a closed
                           one's inside is meshed too, but written in domain only: no inside_NAME)
                           (.obj, .stl, .off, .msh); NAME defaults to its 1-based position (may
                           repeat; at least one)
  --size H                 mesh size (required): every tet's volume is bounded by that of the regular
                           tet of edge H, H^3 / (6 sqrt 2) (TetGen's -a). That bounds every tet, where
                           Gmsh's size is an edge length to aim at, so TetGen makes about 4 times more
                           tets than reference-gmsh at the same H; near a surface the tets also follow
                           the size of its triangles
  --output FILE.msh        Gmsh MSH 4.1 ASCII with the 3D group `domain`, the 2D groups xmin, xmax,
                           ymin, ymax, zmin, zmax and interface_NAME per surface (required)
  --radius-edge Q          radius-edge ratio bound of the refinement (TetGen's -q Q; default 1.414, at
                           least 1: TetGen need not terminate below)
  --min-dihedral D         also a lower bound on dihedral angles, in degrees (TetGen's -q Q/D; default
                           none); TetGen does not reach it (slivers stay) but refines more
  --keep-surface           keep every surface triangle as it is (TetGen's -Y): no Steiner point on the
                           surfaces nor on the box sides, so TetGen 1.5 hardly refines: nearly flat
                           tets next to the surfaces and tets far above the --size bound (a warning
                           says so)
  --report FILE.json       counts, timings, the TetGen switches and quality: equilateral mean ratio
                           min/mean/std and min/max dihedral angle, computed by meccano's own quality
                           functions
  --quiet                  no progress output
  --verbose                TetGen's own progress and statistics on stdout (TetGen's -V; otherwise -Q)
  --help                   this text

Example:
  reference-tetgen --box 0 0 0 1 1 1 --surface meshes/cube_example.obj:patch --size 0.05 \
                   --output reference.msh --report reference.json
)";

using meccano::reference::UsageError;

struct Options {
  meccano::reference::CommonOptions common;
  double radius_edge = 1.414;
  std::optional<double> min_dihedral_deg;
  bool keep_surface = false;
  bool verbose = false;
};

// The largest dihedral angle bound any tet can meet: the equilateral tet's, acos(1/3).
const double equilateral_dihedral_deg = std::acos(1.0 / 3.0) * 180.0 / std::numbers::pi;

Options parse_options(int argc, char** argv) {
  Options options;
  meccano::reference::parse_arguments(argc, argv, usage_text, options.common,
                                      [&](meccano::tools::ArgumentParser& parser) {
    parser.value({"--radius-edge"}, [&](const std::string& text) {
      options.radius_edge = meccano::tools::parse_finite_number("--radius-edge", text);
      if (!(options.radius_edge >= 1.0))
        throw UsageError("--radius-edge must be at least 1 (TetGen need not terminate below)");
    });
    parser.value({"--min-dihedral"}, [&](const std::string& text) {
      options.min_dihedral_deg = meccano::tools::parse_finite_number("--min-dihedral", text);
      if (!(*options.min_dihedral_deg > 0.0 && *options.min_dihedral_deg < equilateral_dihedral_deg))
        throw UsageError("--min-dihedral must lie between 0 and " + std::to_string(equilateral_dihedral_deg) +
                         " degrees (the equilateral tet's)");
    });
    parser.flag({"--keep-surface"}, [&] { options.keep_surface = true; });
    parser.flag({"--verbose"}, [&] { options.verbose = true; });
  });
  if (options.verbose && options.common.quiet) throw UsageError("--quiet and --verbose exclude each other");
  return options;
}

// TetGen's -a is no strict bound: its mesh optimization (-O, on by default) flips tets after the
// refinement (measured on the cube example: the largest tet 1.25 times the bound at H = 0.05, within
// it with -O0). With -Y it stops refining where it would have to split a facet, box sides included
// (H = 0.05: 1 028 tets above the bound, the largest 5 000 times it). Above this factor a warning
// says the bound was not met.
constexpr double volume_bound_slack = 2.0;

// The shortest text that reads back to the same double.
std::string exact(double value) {
  char buffer[32];
  return {buffer, std::to_chars(buffer, buffer + sizeof buffer, value).ptr};
}

// The volume of the regular tet of edge h.
double regular_tet_volume(double h) { return h * h * h / (6.0 * std::numbers::sqrt2); }

// TetGen's switch string: p (a PLC), q with the radius-edge (and dihedral) bound, a with the volume
// bound, M, Y to keep the surfaces, Q quiet or V verbose. Without M TetGen merges adjacent facets that
// are nearly coplanar (dihedral above 179.9 degrees) and re-triangulates them: on the cube example 1 207
// interface faces then left the input surface by up to 7.6e-6.
std::string tetgen_switches(const Options& options) {
  std::ostringstream switches;
  switches << "pq" << exact(options.radius_edge);
  if (options.min_dihedral_deg) switches << '/' << exact(*options.min_dihedral_deg);
  switches << 'a' << exact(regular_tet_volume(*options.common.size)) << 'M';
  if (options.keep_surface) switches << 'Y';
  switches << (options.verbose ? 'V' : 'Q');
  return switches.str();
}

// The facet of one polygon, in TetGen's own allocation scheme (tetgenio frees it with delete[]).
void set_polygon_facet(tetgenio::facet& facet, std::initializer_list<int> corners) {
  tetgenio::init(&facet);
  facet.numberofpolygons = 1;
  facet.polygonlist = new tetgenio::polygon[1];
  tetgenio::polygon& polygon = facet.polygonlist[0];
  tetgenio::init(&polygon);
  polygon.numberofvertices = static_cast<int>(corners.size());
  polygon.vertexlist = new int[corners.size()];
  std::copy(corners.begin(), corners.end(), polygon.vertexlist);
}

// Box corner c has coordinate k at the maximum when bit k of c is set.
Eigen::Vector3d box_corner(const meccano::Box& box, int c) {
  Eigen::Vector3d corner;
  for (int k = 0; k < 3; ++k) corner[k] = (c >> k & 1) ? box.max[k] : box.min[k];
  return corner;
}

// The PLC: the 8 box corners, then every surface's points; the box sides with markers 1..6, then every
// surface triangle with its surface's marker.
void fill_plc(const meccano::Box& box, const std::vector<meccano::TriangleSurface>& surfaces, tetgenio& in) {
  in.firstnumber = 0;
  std::vector<int> first_point{8};
  std::size_t triangles = 0;
  for (const auto& surface : surfaces) {
    first_point.push_back(first_point.back() + static_cast<int>(surface.points.size()));
    triangles += surface.triangles.size();
  }
  in.numberofpoints = first_point.back();
  in.pointlist = new REAL[3 * static_cast<std::size_t>(in.numberofpoints)];
  const auto set_point = [&](int index, const Eigen::Vector3d& p) {
    for (int k = 0; k < 3; ++k) in.pointlist[3 * index + k] = p[k];
  };
  for (int c = 0; c < 8; ++c) set_point(c, box_corner(box, c));
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    for (std::size_t v = 0; v < surfaces[s].points.size(); ++v)
      set_point(first_point[s] + static_cast<int>(v), surfaces[s].points[v]);

  in.numberoffacets = static_cast<int>(6 + triangles);
  in.facetlist = new tetgenio::facet[static_cast<std::size_t>(in.numberoffacets)];
  in.facetmarkerlist = new int[static_cast<std::size_t>(in.numberoffacets)];
  for (int k = 0; k < 3; ++k)
    for (int at_max = 0; at_max < 2; ++at_max) {
      const int side = 2 * k + at_max, a = (k + 1) % 3, b = (k + 2) % 3, base = at_max << k;
      set_polygon_facet(in.facetlist[side], {base, base | 1 << a, base | 1 << a | 1 << b, base | 1 << b});
      in.facetmarkerlist[side] = meccano::box_side_tag(static_cast<meccano::BoxSide>(side));
    }
  int facet = 6;
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    for (const auto& t : surfaces[s].triangles) {
      set_polygon_facet(in.facetlist[facet], {first_point[s] + t[0], first_point[s] + t[1], first_point[s] + t[2]});
      in.facetmarkerlist[facet++] = static_cast<int>(7 + s);
    }
}

// terminatetetgen's codes (tetgen.h), with what the user can do about each.
std::string tetgen_failure(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory (try a larger --size)";
    case 2:
      return "TetGen hit an internal error (a TetGen bug; a slightly different --size or --radius-edge may "
             "avoid it)";
    case 3:
      return "TetGen found a self-intersection in the input, closer than its tolerance although the surfaces "
             "passed meccano's checks";
    case 4: return "TetGen found an input feature (edge, gap) smaller than its relative tolerance 1e-8";
    case 5:
      return "TetGen found two input facets very close to each other (--keep-surface avoids the Steiner points "
             "that cause this)";
    case 10: return "TetGen rejected the input as invalid";
    default: return "TetGen failed with code " + std::to_string(code);
  }
}

// The mesh as TetGen returns it, with each face group in meccano's orientation.
struct ReferenceMesh {
  tetgenio tetgen;                                      // points and tets as TetGen made them
  std::vector<std::vector<std::array<int, 3>>> groups;  // faces of marker m at m - 1: box sides, then surfaces
};

Eigen::Vector3d point(const tetgenio& mesh, int index) {
  return {mesh.pointlist[3 * index], mesh.pointlist[3 * index + 1], mesh.pointlist[3 * index + 2]};
}

// Sorts TetGen's faces into the groups of their markers, box faces pointing out of the box, interface
// faces along the input triangle they lie in. MeshingError for a face TetGen did not put on an input facet.
void orient_face_groups(const meccano::Box& box, const std::vector<meccano::TriangleSurface>& surfaces,
                        ReferenceMesh& mesh) {
  const tetgenio& out = mesh.tetgen;
  std::vector<meccano::TriangleBVH> trees(surfaces.begin(), surfaces.end());
  mesh.groups.assign(6 + surfaces.size(), {});
  const double tolerance = 1e-9 * box.diagonal();
  for (int f = 0; f < out.numberoftrifaces; ++f) {
    const int marker = out.trifacemarkerlist[f];
    std::array<int, 3> face{};
    for (int i = 0; i < 3; ++i) face[i] = out.trifacelist[3 * f + i] - out.firstnumber;
    const Eigen::Vector3d a = point(out, face[0]), b = point(out, face[1]), c = point(out, face[2]);
    const Eigen::Vector3d normal = (b - a).cross(c - a);
    if (marker < 1 || marker > static_cast<int>(mesh.groups.size()))
      throw meccano::MeshingError("TetGen returned face " + std::to_string(f + 1) + " with marker " +
                                  std::to_string(marker) + ", which is no input facet's");
    bool along;
    if (marker <= 6) {
      const int side = marker - 1, axis = side / 2;
      along = (side % 2 == 1) == (normal[axis] > 0.0);
    } else {
      const meccano::TriangleBVH& tree = trees[marker - 7];
      const meccano::ClosestPoint nearest = tree.closest_point((a + b + c) / 3.0);
      if (nearest.squared_distance > tolerance * tolerance)
        throw meccano::MeshingError("TetGen put face " + std::to_string(f + 1) + " of surface " +
                                    surfaces[marker - 7].name + " off the surface");
      const meccano::Triangle3& parent = tree.triangle(nearest.triangle);
      along = normal.dot((parent[1] - parent[0]).cross(parent[2] - parent[0])) > 0.0;
    }
    if (!along) std::swap(face[1], face[2]);
    mesh.groups[marker - 1].push_back(face);
  }
}

// MSH 4.1 ASCII: one volume entity (tag 1, physical group 1 `domain`) and one surface entity per face
// group, whose entity tag and physical tag are its TetGen marker (1..6 the box sides, 7.. the surfaces,
// as meccano-immerse numbers them). All nodes in one block; elements numbered faces first, then tets.
void write_msh41(const ReferenceMesh& mesh, const std::vector<meccano::TriangleSurface>& surfaces,
                 const meccano::Box& box, const std::string& path) {
  const tetgenio& out = mesh.tetgen;
  const auto group_name = [&](std::size_t g) -> std::string {
    return g < 6 ? meccano::box_side_name(static_cast<meccano::BoxSide>(g)) : "interface_" + surfaces[g - 6].name;
  };
  meccano::write_file_atomically(path, [&](std::ostream& file) {
    const std::string bounds = exact(box.min.x()) + ' ' + exact(box.min.y()) + ' ' + exact(box.min.z()) + ' ' +
                               exact(box.max.x()) + ' ' + exact(box.max.y()) + ' ' + exact(box.max.z());
    const std::size_t groups = mesh.groups.size();
    file << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
    file << "$PhysicalNames\n" << groups + 1 << "\n3 1 \"domain\"\n";
    for (std::size_t g = 0; g < groups; ++g) file << "2 " << g + 1 << " \"" << group_name(g) << "\"\n";
    file << "$EndPhysicalNames\n";

    file << "$Entities\n0 0 " << groups << " 1\n";
    for (std::size_t g = 0; g < groups; ++g) file << g + 1 << ' ' << bounds << " 1 " << g + 1 << " 0\n";
    file << "1 " << bounds << " 1 1 0\n$EndEntities\n";

    const int nodes = out.numberofpoints;
    file << "$Nodes\n1 " << nodes << " 1 " << nodes << "\n3 1 0 " << nodes << '\n';
    for (int v = 1; v <= nodes; ++v) file << v << '\n';
    for (int v = 0; v < nodes; ++v)
      file << exact(out.pointlist[3 * v]) << ' ' << exact(out.pointlist[3 * v + 1]) << ' '
           << exact(out.pointlist[3 * v + 2]) << '\n';
    file << "$EndNodes\n";

    std::size_t elements = static_cast<std::size_t>(out.numberoftetrahedra);
    for (const auto& faces : mesh.groups) elements += faces.size();
    file << "$Elements\n" << groups + 1 << ' ' << elements << " 1 " << elements << '\n';
    std::size_t tag = 0;
    for (std::size_t g = 0; g < groups; ++g) {
      file << "2 " << g + 1 << " 2 " << mesh.groups[g].size() << '\n';
      for (const auto& face : mesh.groups[g])
        file << ++tag << ' ' << face[0] + 1 << ' ' << face[1] + 1 << ' ' << face[2] + 1 << '\n';
    }
    file << "3 1 4 " << out.numberoftetrahedra << '\n';
    for (int t = 0; t < out.numberoftetrahedra; ++t) {
      file << ++tag;
      for (int i = 0; i < 4; ++i) file << ' ' << out.tetrahedronlist[4 * t + i] - out.firstnumber + 1;
      file << '\n';
    }
    file << "$EndElements\n";
  });
}

int run(const Options& options) {
  using meccano::reference::Clock;
  const meccano::reference::CommonOptions& common = options.common;
  // No TetGen failure for what meccano-immerse would reject: start_run validates the surfaces first.
  const auto [start, progress, surfaces] = meccano::reference::start_run(common);

  tetgenio in;
  fill_plc(common.box, surfaces, in);
  std::string switches = tetgen_switches(options);  // not const: tetrahedralize takes a char*
  progress.say("tetgen: switches ", switches, " (volume bound ", regular_tet_volume(*common.size),
               ", the regular tet of edge ", *common.size, ")");
  ReferenceMesh mesh;
  const auto meshing_start = Clock::now();
  try {
    tetrahedralize(switches.data(), &in, &mesh.tetgen);
  } catch (int code) {
    throw meccano::MeshingError(tetgen_failure(code));
  }
  const double meshing_seconds = meccano::reference::seconds_since(meshing_start);
  const tetgenio& out = mesh.tetgen;
  if (out.numberoftetrahedra == 0) throw meccano::MeshingError("TetGen produced no tetrahedra");
  orient_face_groups(common.box, surfaces, mesh);

  std::vector<std::pair<std::string, std::size_t>> interface_triangles;
  for (std::size_t s = 0; s < surfaces.size(); ++s)
    interface_triangles.emplace_back(surfaces[s].name, mesh.groups[6 + s].size());
  const auto summary = meccano::reference::summarize_tets(static_cast<std::size_t>(out.numberoftetrahedra),
                                                          static_cast<std::size_t>(out.numberofpoints),
                                                          [&](std::size_t t) {
    meccano::TetPoints p;
    for (std::size_t i = 0; i < 4; ++i) p[i] = point(out, out.tetrahedronlist[4 * t + i] - out.firstnumber);
    return p;
  });
  const meccano::reference::ReferenceRun record{"reference-tetgen", *common.size, std::move(interface_triangles),
                                                summary, meshing_seconds};
  progress.say("tetgen: ", meccano::reference::describe(record.mesh), " in ", record.meshing_seconds, " s");
  if (const double bound = regular_tet_volume(*common.size); summary.max_volume > volume_bound_slack * bound)
    progress.say("warning: TetGen left tets far above the volume bound ", bound, " (the largest ", summary.max_volume,
                 options.keep_surface ? "): with --keep-surface it may not split the facets to refine" : ")");

  meccano::reference::write_outputs(
      common, progress, [&](const std::string& path) { write_msh41(mesh, surfaces, common.box, path); },
      [&](const std::string& path) {
    meccano::reference::write_report(
        record,
        [&](meccano::JsonWriter& json) {
      json.key("switches").value(switches).key("radius_edge").value(options.radius_edge);
      if (options.min_dihedral_deg) json.key("min_dihedral_bound_deg").value(*options.min_dihedral_deg);
      else json.key("min_dihedral_bound_deg").null();
      json.key("keep_surface").value(options.keep_surface).key("volume_bound").value(regular_tet_volume(*common.size));
        },
        meccano::reference::seconds_since(start), path);
      });
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return meccano::tools::run_reporting_errors("reference-tetgen", [&] { return run(parse_options(argc, argv)); });
}
