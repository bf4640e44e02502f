#pragma once

namespace dem {

// PID law of LIGGGHTS fix mesh/surface/stress/servo (ctrlPV force). The process value pv is
// the force the particles exert on the wall, projected on the servo axis. The set point is
// -target_val, so a negative target_val drives the wall towards -axis until the particles push
// back along +axis with |target_val|:
//   err = sp - pv,  sum += err dt,  dpv = -(pv - pv_old) / dt,
//   v   = -vel_max (kp err + ki sum + kd dpv) / |sp|   (speed along the axis, m/s),
// limited to |v| <= vel_max; when limited and ki > 0 the sum is reset so that the unlimited
// output equals the limit (anti-wind-up).
class ServoController {
 public:
  double kp = 0.01, ki = 0.0, kd = 0.0;
  double vel_max = 0.0;  // m/s

  // Throws EngineError for a zero target.
  void set_target(double target_val);
  double target() const { return -sp_; }
  // New axial speed of the wall (m/s) from the process value (N) after a step of dt (s).
  double update(double pv, double dt);
  void reset_integral() { sum_err_ = 0.0; }

 private:
  double sp_ = 0.0;
  double sum_err_ = 0.0;
  double pv_old_ = 0.0;
};

}  // namespace dem
