// Reference trajectories. A source is queried once per control period with a non-decreasing time, so
// stateful generators (the potential field integrates a double integrator) fit the same interface.
#pragma once

#include <cmath>
#include <cstdint>
#include <memory>

#include "sowing_robot/core/common/types.h"

namespace sowing_robot {
namespace core {

class ReferenceSource {
 public:
  virtual ~ReferenceSource() = default;
  /// Back to the state at t = 0.
  void reset() {
    last_ = Reference{};
    last_t_ = 0.0;
    rejected_ = 0;
    restart();
  }
  /// Reference at time t [s]; t never decreases between two calls after reset(). A non-finite t is
  /// rejected: the generator's state is untouched and the previous reference is returned again (the
  /// default Reference, at the origin, before the first one); rejected() counts these.
  /// The reference returned stays valid (and unchanged) until the next call of next() or reset(): it is
  /// the source's own copy, so the closed loop does not copy it once more every period.
  const Reference& next(double t) {
    if (!std::isfinite(t)) {
      ++rejected_;
      return last_;
    }
    last_ = evaluate(t);
    last_t_ = t;
    return last_;
  }
  /// The time of the last accepted next() since reset() [s] (0 before the first): where a wrapper that
  /// runs the source at its own pace (the speed governor) has taken it.
  double lastTime() const { return last_t_; }
  /// Number of calls to next() refused since reset() for a non-finite time.
  std::int64_t rejected() const { return rejected_; }
  /// An independent copy in its reset state (the PSO tuner gives each thread its own).
  virtual std::unique_ptr<ReferenceSource> clone() const = 0;

 protected:
  /// reset() of the concrete generator.
  virtual void restart() = 0;
  /// next() of the concrete generator, for a finite t.
  virtual Reference evaluate(double t) = 0;

 private:
  Reference last_;
  double last_t_ = 0.0;
  std::int64_t rejected_ = 0;
};

/// The thesis's sowing line (Table 5.2): x_d = x0 + v_r t, y_d = row_y, theta_d = heading 0.
class LineReference : public ReferenceSource {
 public:
  LineReference(double v_r = 1.0, double row_y = 3.0, double x0 = 0.0) : v_r_(v_r), row_y_(row_y), x0_(x0) {}
  std::unique_ptr<ReferenceSource> clone() const override {
    auto c = std::make_unique<LineReference>(*this);
    c->reset();
    return c;
  }

 protected:
  void restart() override {}
  Reference evaluate(double t) override {
    // Every field in one initialiser: built in registers, not zeroed on the stack and patched.
    return Reference{Pose2D{x0_ + v_r_ * t, row_y_, 0.0}, v_r_, 0.0, 0.0, 0.0, true, false};
  }

 private:
  double v_r_, row_y_, x0_;
};

}  // namespace core
}  // namespace sowing_robot
