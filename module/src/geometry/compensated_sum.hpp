// Neumaier's compensated sum (internal): millions of tet volumes add up to the box volume to round-off,
// where a plain double sum drifts by about 1e-10 relative at 15 M tets.
#pragma once

#include <cmath>

namespace meccano {

class CompensatedSum {
 public:
  void add(double x) {
    const double t = sum_ + x;
    compensation_ += std::abs(sum_) >= std::abs(x) ? (sum_ - t) + x : (x - t) + sum_;
    sum_ = t;
  }
  double value() const { return sum_ + compensation_; }

 private:
  double sum_ = 0.0, compensation_ = 0.0;
};

}  // namespace meccano
