// Reference trajectories. A source is queried once per control period with a non-decreasing time, so
// stateful generators (the potential field integrates a double integrator) fit the same interface.
#pragma once

#include <memory>

#include "sowing_robot/core/types.h"

namespace sowing_robot {
namespace core {

class ReferenceSource {
 public:
  virtual ~ReferenceSource() = default;
  /// Back to the state at t = 0.
  virtual void reset() = 0;
  /// Reference at time t [s]; t never decreases between two calls after reset().
  virtual Reference next(double t) = 0;
  /// An independent copy in its reset state (the PSO tuner gives each thread its own).
  virtual std::unique_ptr<ReferenceSource> clone() const = 0;
};

/// The thesis's sowing line (Table 5.2): x_d = x0 + v_r t, y_d = row_y, theta_d = heading 0.
class LineReference : public ReferenceSource {
 public:
  LineReference(double v_r = 1.0, double row_y = 3.0, double x0 = 0.0) : v_r_(v_r), row_y_(row_y), x0_(x0) {}
  void reset() override {}
  Reference next(double t) override {
    Reference r;
    r.pose = {x0_ + v_r_ * t, row_y_, 0.0};
    r.v = v_r_;
    return r;
  }
  std::unique_ptr<ReferenceSource> clone() const override { return std::make_unique<LineReference>(*this); }

 private:
  double v_r_, row_y_, x0_;
};

}  // namespace core
}  // namespace sowing_robot
