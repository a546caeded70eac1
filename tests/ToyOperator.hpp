#pragma once
// A coupled operator with the structure of the IB problem and an exact solution, for testing the integrators:
// each node carries a "fluid parcel" velocity v (interpolation and spreading are the identity), the membrane force
// is a spring f(X) = -K (X - R), and the fluid step is Crank-Nicolson for  rho dv/dt = -a v + F:
//   rho (v^{n+1} - v^n)/dt = -(a/2)(v^{n+1} + v^n) + F^{n+1/2}.
// Continuous problem: x'' + (a/rho) x' + (K/rho) x = 0 per component (a damped oscillator).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "immerse/timestep/CoupledOperator.hpp"

namespace immerse::testing {

class ToyOperator final : public CoupledOperator {
 public:
  ToyOperator(std::vector<double> X0, std::vector<double> rest, double K, double a, double rho)
      : X_(std::move(X0)), R_(std::move(rest)), v_(X_.size(), 0.0), trial_(X_.size()), K_(K), a_(a), rho_(rho) {}

  std::size_t size() const override { return X_.size(); }
  std::span<const double> positions() const override { return X_; }
  std::span<const double> node_velocity() const override { return v_; }
  double length_scale() const override { return 1.0; }

  void trial_velocity(std::span<const double> Xf, double theta, std::span<const double>, double dt,
                      std::span<double> U) override {
    ++solves_;
    for (std::size_t i = 0; i < X_.size(); ++i) {
      const double F = -K_ * ((1 - theta) * (X_[i] - R_[i]) + theta * (Xf[i] - R_[i]));
      trial_[i] = ((rho_ / dt - a_ / 2) * v_[i] + F) / (rho_ / dt + a_ / 2);
      U[i] = trial_[i];
    }
    trial_X_.assign(Xf.begin(), Xf.end());
  }
  bool trial_matches(std::span<const double> X) const override { return std::ranges::equal(X, trial_X_); }
  void committed_velocity(std::span<const double>, std::span<double> U) override {
    std::copy(v_.begin(), v_.end(), U.begin());
  }
  void commit(std::span<const double> X, double dt) override {
    X_.assign(X.begin(), X.end());
    v_ = trial_;
    time_ += dt;
  }
  std::size_t fluid_solves() const override { return solves_; }

  double time() const { return time_; }
  const std::vector<double>& velocity() const { return v_; }

  /// Exact x(t) and v(t) of the damped oscillator with x(0) = x0 (relative to rest), v(0) = 0; underdamped.
  std::pair<double, double> exact(double x0, double t) const {
    const double g = a_ / (2 * rho_), w0sq = K_ / rho_;
    const double w = std::sqrt(w0sq - g * g);
    if (!(w0sq > g * g)) throw std::logic_error("ToyOperator::exact needs an underdamped oscillator");
    const double x = x0 * std::exp(-g * t) * (std::cos(w * t) + g / w * std::sin(w * t));
    const double v = -x0 * std::exp(-g * t) * (w0sq / w) * std::sin(w * t);
    return {x, v};
  }

 private:
  std::vector<double> X_, R_, v_, trial_, trial_X_;
  double K_, a_, rho_;
  double time_ = 0;
  std::size_t solves_ = 0;
};

}  // namespace immerse::testing
