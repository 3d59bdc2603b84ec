// A triangulated surface S to be immersed: the type every stage shares. The readers that load one are in
// io/surface_readers.hpp; the requirements it must meet (a disk inside the box, no self-intersection, ...)
// are checked by surface/validation.hpp.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <vector>

namespace meccano {

struct TriangleSurface {
  std::string name;    // used in output group names, e.g. interface_NAME
  std::string source;  // file the surface came from (for messages); empty when built in code
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> triangles;
};

// The sum of the triangles' areas.
double surface_area(const TriangleSurface& surface);

}  // namespace meccano
