// The axis-aligned box that the meccano mesh fills.
#pragma once

#include <Eigen/Core>

namespace meccano {

struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;

  Eigen::Vector3d extent() const { return max - min; }
  double diagonal() const { return extent().norm(); }
};

}  // namespace meccano
