#include "mesh/servo_controller.h"

#include <cmath>

#include "deck/errors.h"

namespace dem {

void ServoController::set_target(double target_val) {
  if (target_val == 0.0 || !std::isfinite(target_val))
    throw EngineError("servo target_val must be a non-zero number");
  sp_ = -target_val;
}

double ServoController::update(double pv, double dt) {
  const double err = sp_ - pv;
  sum_err_ += err * dt;
  const double dpv = -(pv - pv_old_) / dt;
  pv_old_ = pv;
  const double inv_sp = 1.0 / std::fabs(sp_);
  double v = -vel_max * (kp * err + ki * sum_err_ + kd * dpv) * inv_sp;
  if (std::fabs(v) > vel_max) {
    v = v > 0.0 ? vel_max : -vel_max;
    // Integral state that makes the unlimited output exactly the limit.
    if (ki > 0.0) sum_err_ = (-v / (vel_max * inv_sp) - kp * err - kd * dpv) / ki;
  }
  return v;
}

}  // namespace dem
