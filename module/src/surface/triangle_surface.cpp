#include <meccano/surface/triangle_surface.hpp>

#include <Eigen/Geometry>

namespace meccano {

double surface_area(const TriangleSurface& surface) {
  double twice = 0.0;
  for (const auto& [a, b, c] : surface.triangles)
    twice += (surface.points[b] - surface.points[a]).cross(surface.points[c] - surface.points[a]).norm();
  return 0.5 * twice;
}

}  // namespace meccano
