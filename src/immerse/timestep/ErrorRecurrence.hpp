#pragma once
// The implicit step's initial guess, corrected by the history of its errors.
//
// Step 1 of §3 starts Newton from the linear extrapolation X_e^{n+1} = X^n + (dt/dt^{n-1})(X^n - X^{n-1}); it misses
// the converged X^{n+1} by e^{n+1} = X^{n+1} - X_e^{n+1}. The membrane modes make these errors a sequence with a
// short linear recurrence: under the trapezoidal rule (29) a stiff mode is multiplied by r = (1 - dt l/2)/(1 + dt l/2)
// ~ -1 per step (it rings), a soft one by r ~ 1, and a sequence made of two such families obeys
//
//   e^{k} = a1 e^{k-1} + a2 e^{k-2}    (a1 = r1 + r2, a2 = -r1 r2).
//
// The coefficients are fitted by least squares to the last three errors (e^n on e^{n-1}, e^{n-2}; one term when
// only two are known or the two-term fit is singular) and the next error is predicted,
//
//   X^(0) = X_e^{n+1} + a1 e^n + a2 e^{n-1}.
//
// The prediction is skipped when the fit explains less than three quarters of e^n (relative residual above 1/2),
// or when the last prediction (the same fit one step earlier, recomputed from the stored errors) missed e^n by more
// than e^n itself (the recurrence stopped holding: the extrapolation alone was better). The history is dropped
// when dt changes (the errors scale with it). Measured on §4.4 (docs/time-integration.md):
// the prediction misses e^{n+1} by 2-3 % with the paper's cells, by 12-17 % with 100x stiffer ones.
#include <cstddef>
#include <deque>
#include <span>
#include <vector>

namespace immerse {

class ErrorRecurrence {
 public:
  /// Terms of the fitted recurrence the next prediction uses: 0 (none), 1 or 2.
  int terms(double dt) const;
  /// Adds the predicted error of a step of length dt to X (nothing when terms(dt) == 0).
  void predict(double dt, std::span<double> X) const;
  /// Records the error of a step of length dt that started from the linear extrapolation.
  void record(double dt, std::span<const double> error);
  void clear();

  /// The stored errors, oldest first, concatenated (for checkpoints), and the step they belong to.
  std::vector<double> errors() const;
  double dt() const { return dt_; }
  /// Replaces the history by errors() of vectors of length n recorded with step dt.
  void restore(std::span<const double> errors, std::size_t n, double dt);

 private:
  struct Fit {
    int terms = 0;
    double a1 = 0, a2 = 0;
  };
  // The fit of e_[m-1] on e_[m-2] (and e_[m-3]), which predicts e_[m].
  Fit fit(std::size_t m) const;
  Fit next_fit() const;
  // Four errors: the last three for the next prediction, and one more to recompute the last prediction.
  static constexpr std::size_t kDepth = 4;
  std::deque<std::vector<double>> e_;
  double dt_ = 0;
};

}  // namespace immerse
