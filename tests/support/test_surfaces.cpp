#include "test_surfaces.hpp"

#include <meccano/io/surface_readers.hpp>
#include <meccano/surface/closed_surface.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>
#include <utility>

namespace meccano::testing {

namespace {

using Eigen::Vector3d;
using std::numbers::pi;

// Image of a (nu x nv)-cell grid of [0,1]^2 under `map`; normals along d(map)/du x d(map)/dv.
TriangleSurface parametric_patch(const std::function<Vector3d(double, double)>& map, int nu, int nv, std::string name) {
  TriangleSurface surface;
  surface.name = std::move(name);
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) surface.points.push_back(map(double(i) / nu, double(j) / nv));
  }
  const auto vertex = [nu](int i, int j) { return j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      surface.triangles.push_back({vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)});
      surface.triangles.push_back({vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)});
    }
  }
  return surface;
}

// Uniform in [0, 1) from the 53 high bits: unlike std::uniform_real_distribution, the same on every
// standard library.
double uniform(std::mt19937_64& generator) { return double(generator() >> 11) * 0x1.0p-53; }

}  // namespace

TriangleSurface graph_patch(const std::function<double(double, double)>& f, std::array<double, 2> x_range,
                            std::array<double, 2> y_range, int n, std::string name) {
  return parametric_patch(
      [&](double u, double v) {
    const double x = x_range[0] + u * (x_range[1] - x_range[0]);
    const double y = y_range[0] + v * (y_range[1] - y_range[0]);
    return Vector3d(x, y, f(x, y));
      },
      n, n, std::move(name));
}

TriangleSurface sawtooth_patch(int n) {
  const auto height = [](double x, double y) { return 0.45 + 0.06 * std::sin(2 * pi * x) + 0.1 * y; };
  TriangleSurface surface = graph_patch(height, {0.2, 0.8}, {0.2, 0.8}, n, "sawtooth");
  const double cell = 0.6 / n;
  for (int k = 0; k < n; ++k) {
    const double x = 0.2 + (k + 0.5) * cell;
    const int apex = static_cast<int>(surface.points.size());
    surface.points.emplace_back(x, 0.2 - 0.6 * cell, height(x, 0.2 - 0.6 * cell));
    surface.triangles.push_back({k + 1, k, apex});  // the patch has edge k -> k + 1: the tooth runs against it
  }
  return surface;
}

TriangleSurface tilted_plane(int n) {
  return graph_patch([](double x, double y) { return 0.35 + 0.3 * x + 0.1 * y; }, {0.1, 0.9}, {0.1, 0.9}, n,
                     "tilted_plane");
}

TriangleSurface near_vertical_patch(int n) {
  // Slope of x against y and z at most 0.04 + 0.008 pi / 0.6 < tan 5 degrees.
  return parametric_patch(
      [](double u, double v) {
    const double y = 0.2 + 0.6 * u;
    const double z = 0.2 + 0.6 * v;
    return Vector3d(0.5 + 0.04 * (z - 0.5) + 0.008 * std::sin(pi * u) * std::sin(pi * v), y, z);
      },
      n, n, "near_vertical");
}

TriangleSurface saddle(int n) {
  return graph_patch([](double x, double y) { return 0.5 + 1.2 * (x - 0.5) * (y - 0.5); }, {0.1, 0.9}, {0.1, 0.9}, n,
                     "saddle");
}

TriangleSurface spherical_cap(int n) {
  // Ring k (polar angle k/n of the cap's) has 6k vertices; consecutive rings are zipped together by
  // azimuth, which gives 6 (2k - 1) triangles between rings k - 1 and k, all oriented outwards.
  const Vector3d centre(0.5, 0.5, 0.3);
  const double radius = 0.4;
  const double polar_angle = 65.0 * pi / 180.0;
  TriangleSurface surface;
  surface.name = "spherical_cap";
  surface.points.push_back(centre + Vector3d(0.0, 0.0, radius));
  std::vector<int> inner{0};
  for (int k = 1; k <= n; ++k) {
    const double phi = polar_angle * k / n;
    const int count = 6 * k;
    std::vector<int> outer;
    for (int j = 0; j < count; ++j) {
      const double theta = 2.0 * pi * j / count;
      outer.push_back(static_cast<int>(surface.points.size()));
      surface.points.push_back(
          centre + radius * Vector3d(std::sin(phi) * std::cos(theta), std::sin(phi) * std::sin(theta), std::cos(phi)));
    }
    const int a = static_cast<int>(inner.size());
    const int b = count;
    int i = 0;
    int j = 0;
    // Advance along whichever ring's next vertex comes first in azimuth (exact integer comparison
    // of (i + 1) / a against (j + 1) / b); the centre (a = 1) only fans.
    while (j < b || (a > 1 && i < a)) {
      const bool advance_outer = j < b && (a == 1 || i == a || (j + 1) * a <= (i + 1) * b);
      if (advance_outer) {
        surface.triangles.push_back({inner[i % a], outer[j], outer[(j + 1) % b]});
        ++j;
      } else {
        surface.triangles.push_back({inner[i], outer[j % b], inner[(i + 1) % a]});
        ++i;
      }
    }
    inner = std::move(outer);
  }
  return surface;
}

TriangleSurface strongly_curved_sheet(int n) {
  const double start = -20.0 * pi / 180.0;
  const double span = 220.0 * pi / 180.0;
  return parametric_patch(
      [=](double u, double v) {
    const double theta = start + span * u;
    return Vector3d(0.5 + 0.3 * std::cos(theta), 0.2 + 0.6 * v, 0.5 + 0.3 * std::sin(theta));
      },
      2 * n, n, "strongly_curved_sheet");
}

std::vector<TriangleSurface> stacked_pair(int n) {
  const auto bump = [](double x, double y) {
    return 0.08 * std::sin(pi * (x - 0.15) / 0.7) * std::sin(pi * (y - 0.15) / 0.7);
  };
  return {graph_patch([&](double x, double y) { return 0.35 + bump(x, y); }, {0.15, 0.85}, {0.15, 0.85}, n,
                      "stacked_lower"),
          graph_patch([&](double x, double y) { return 0.65 + bump(x, y); }, {0.15, 0.85}, {0.15, 0.85}, n,
                      "stacked_upper")};
}

TriangleSurface paper_like_patch(int n) {
  return graph_patch(
      [](double x, double y) {
    const double u = (x - 0.2) / 0.6;
    const double v = (y - 0.2) / 0.6;
    return 0.42 + 0.12 * u * v + 0.10 * std::sin(pi * u) * std::sin(pi * v);
      },
      {0.2, 0.8}, {0.2, 0.8}, n, "paper_like");
}

TriangleSurface ellipsoid(const Vector3d& centre, const Vector3d& radii, int n, std::string name) {
  return triangulate_star_shaped([&](const Vector3d& d) -> Vector3d { return centre + radii.cwiseProduct(d); }, n,
                                 std::move(name));
}

TriangleSurface sphere(int n) { return ellipsoid(Vector3d::Constant(0.5), Vector3d::Constant(0.3), n, "sphere"); }

TriangleSurface bumpy_blob(int n) {
  const std::array<Vector3d, 3> bumps{Vector3d(1, 0.3, 0.2).normalized(), Vector3d(-0.4, 1, 0.5).normalized(),
                                      Vector3d(0.1, -0.6, -1).normalized()};
  return triangulate_star_shaped(
      [&](const Vector3d& d) -> Vector3d {
        double b = 0.0;
        for (const Vector3d& bump : bumps) b += std::exp(-(d - bump).squaredNorm() / 0.3);
        return Vector3d::Constant(0.5) + 0.25 * (1.0 + 0.25 * b) * d;
      },
      n, "bumpy_blob");
}

TriangleSurface closed_torus(int n) {
  TriangleSurface surface;
  surface.name = "torus";
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double u = 2 * pi * i / n, v = 2 * pi * j / n;
      surface.points.push_back(Vector3d(0.5 + (0.25 + 0.1 * std::cos(v)) * std::cos(u),
                                        0.5 + (0.25 + 0.1 * std::cos(v)) * std::sin(u), 0.5 + 0.1 * std::sin(v)));
    }
  auto at = [n](int i, int j) { return (j % n) * n + (i % n); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      surface.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      surface.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return surface;
}

std::vector<NamedSurfaces> named_test_surfaces(int n) {
  TriangleSurface irregular = perturbed(paper_like_patch(n), 0.2, 1);
  irregular.name = "perturbed_paper_like";
  return {{"tilted_plane", {tilted_plane(n)}},
          {"near_vertical", {near_vertical_patch(n)}},
          {"saddle", {saddle(n)}},
          {"spherical_cap", {spherical_cap(n)}},
          {"strongly_curved_sheet", {strongly_curved_sheet(n)}},
          {"stacked_pair", stacked_pair(n)},
          {"paper_like", {paper_like_patch(n)}},
          {"perturbed_paper_like", {std::move(irregular)}}};
}

TriangleSurface perturbed(TriangleSurface surface, double amplitude, std::uint64_t seed) {
  const std::size_t count = surface.points.size();
  std::vector<double> shortest_edge(count, std::numeric_limits<double>::infinity());
  std::vector<Vector3d> normal(count, Vector3d::Zero());
  std::map<std::pair<int, int>, int> edge_uses;
  for (const auto& t : surface.triangles) {
    const Vector3d area_normal =
        (surface.points[t[1]] - surface.points[t[0]]).cross(surface.points[t[2]] - surface.points[t[0]]);
    for (int k = 0; k < 3; ++k) {
      const int a = t[k];
      const int b = t[(k + 1) % 3];
      const double length = (surface.points[a] - surface.points[b]).norm();
      shortest_edge[a] = std::min(shortest_edge[a], length);
      shortest_edge[b] = std::min(shortest_edge[b], length);
      normal[a] += area_normal;
      ++edge_uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::vector<bool> on_rim(count, false);
  for (const auto& [edge, uses] : edge_uses) {
    if (uses == 1) on_rim[edge.first] = on_rim[edge.second] = true;
  }
  // Offsets come from the original positions, so neighbours can at most shorten an edge by
  // 2 * amplitude of its length.
  std::vector<Vector3d> offsets(count, Vector3d::Zero());
  std::mt19937_64 generator(seed);
  for (std::size_t v = 0; v < count; ++v) {
    if (on_rim[v] || normal[v].isZero()) continue;
    const Vector3d n = normal[v].normalized();
    const Vector3d t1 = n.unitOrthogonal();
    const Vector3d t2 = n.cross(t1);
    const double angle = 2.0 * pi * uniform(generator);
    const double length = amplitude * shortest_edge[v] * std::sqrt(uniform(generator));
    offsets[v] = length * (std::cos(angle) * t1 + std::sin(angle) * t2);
  }
  for (std::size_t v = 0; v < count; ++v) surface.points[v] += offsets[v];
  return surface;
}

TriangleSurface scaled_into(TriangleSurface surface, const Box& box) {
  for (Vector3d& p : surface.points) p = box.min + p.cwiseProduct(box.extent());
  return surface;
}

double largest_extent(const TriangleSurface& surface) {
  Vector3d lo = surface.points.front(), hi = lo;
  for (const Vector3d& p : surface.points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return (hi - lo).maxCoeff();
}

Box box_around(const TriangleSurface& surface, double margin) {
  Box box{surface.points.front(), surface.points.front()};
  for (const Vector3d& p : surface.points) {
    box.min = box.min.cwiseMin(p);
    box.max = box.max.cwiseMax(p);
  }
  const double grow = margin * box.extent().maxCoeff();
  box.min.array() -= grow;
  box.max.array() += grow;
  return box;
}

std::string shared_fault(const std::string& file) {
  const std::filesystem::path path = std::filesystem::path(MECCANO_FAULTS_DIR) / file;
  return std::filesystem::exists(path) ? path.string() : std::string();
}

std::optional<TriangleSurface> read_shared_fault(const std::string& file) {
  const std::string path = shared_fault(file);
  if (path.empty()) return std::nullopt;
  TriangleSurface surface = read_surface(path);
  surface.name = "fault";
  return surface;
}

std::vector<SurfaceCase> surface_cases(int n, bool with_perturbed) {
  std::vector<SurfaceCase> all;
  const Box unit{{0, 0, 0}, {1, 1, 1}};
  const Box bar{{-1, 0, 0}, {1, 1, 1}};
  const Box slab{{0, 0, 0}, {1, 1.5, 0.5}};
  for (auto& named : named_test_surfaces(n)) {
    all.push_back({named.name + "_unit_cube_lr16", named.surfaces, unit, 1.0 / 16});
    all.push_back({named.name + "_unit_cube_lr32", named.surfaces, unit, 1.0 / 32});
    std::vector<TriangleSurface> in_bar, in_slab, moved;
    for (const auto& s : named.surfaces) {
      in_bar.push_back(scaled_into(s, bar));
      in_slab.push_back(scaled_into(s, slab));
      moved.push_back(perturbed(s, 0.2, 7));
    }
    all.push_back({named.name + "_2x1x1_box_lr16", in_bar, bar, 1.0 / 16});
    all.push_back({named.name + "_flat_box_lr40", in_slab, slab, 1.0 / 40});
    if (with_perturbed) all.push_back({named.name + "_perturbed_lr24", moved, unit, 1.0 / 24});
  }
  return all;
}

std::vector<std::pair<int, int>> rim_edges(const TriangleSurface& surface) {
  std::vector<std::pair<int, int>> edges, rim;
  for (const auto& t : surface.triangles)
    for (int k = 0; k < 3; ++k) edges.push_back(std::minmax(t[k], t[(k + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) rim.push_back(edges[i]);
    i = j;
  }
  return rim;
}

double distance_to_rim(const TriangleSurface& surface, const Eigen::Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [first, second] : rim_edges(surface)) {
    const Eigen::Vector3d a = surface.points[first], b = surface.points[second];
    const double s = std::clamp((x - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    best = std::min(best, (a + s * (b - a) - x).norm());
  }
  return best;
}

std::string write_obj(const std::string& path, const TriangleSurface& surface) {
  std::ofstream out(path);
  out.precision(17);
  for (const auto& p : surface.points) out << "v " << p.x() << ' ' << p.y() << ' ' << p.z() << '\n';
  for (const auto& t : surface.triangles) out << "f " << t[0] + 1 << ' ' << t[1] + 1 << ' ' << t[2] + 1 << '\n';
  if (!out.flush()) throw std::runtime_error("cannot write " + path);
  return path;
}

}  // namespace meccano::testing
