#pragma once
// The implicit step's initial guess, corrected by the history of its errors.
//
// Step 1 of §3 starts Newton from the linear extrapolation X_e^{n+1} = X^n + (dt/dt^{n-1})(X^n - X^{n-1}); it misses
// the converged X^{n+1} by e^{n+1} = X^{n+1} - X_e^{n+1}. The membrane modes make these errors a sequence with a
// short linear recurrence: under the trapezoidal rule (29) a mode of stiffness l is multiplied by
// r = (1 - dt l/2)/(1 + dt l/2) per step (a stiff one rings, r ~ -1; a soft one decays, r ~ 1), and a sequence made of
// t such families obeys
//
//   e^{k} = a1 e^{k-1} + ... + at e^{k-t}      (the a's: the coefficients of prod_j (z - r_j)).
//
// Each membrane (block of unknowns) gets its own recurrence, its cells having their own modes: up to five terms,
// fitted by least squares to the last two errors (e^n and e^{n-1} on the errors before each; one error and fewer
// terms while the history is short; a term less while the fit is singular), and the next error is predicted,
//
//   X^(0) = X_e^{n+1} + a1 e^n + ... + at e^{n-t+1}.
//
// A block's prediction is skipped when its fit explains less than three quarters of its errors (relative residual
// above 1/2; the fit needs more equations than terms), or when the same fit one step earlier (recomputed from the
// stored errors, whether or not it was used) would have missed e^n by more than e^n itself (the recurrence stopped
// holding: the extrapolation alone was better). The history is dropped when dt changes (the errors scale with it).
//
// Two rules keep the guess from moving further than the errors justify (norms over the block):
// - Resolution. An error is computed from positions, to their round-off (~1e-16 ||X||); a fit uses only the errors
//   after the last one not above kResolved ||X^n|| = 1e4 eps ||X^n||. The dependence test above is relative to each
//   error's own size: a round-off-sized error passes it as independent, and least squares gives it a coefficient as
//   large as the ratio of the sizes, which the prediction then applies to a larger error. A red cell at rest records
//   such errors (round-off where Newton accepts an unpredicted X^(0) at once, ~1e-8 ||X|| elsewhere), and its guesses
//   were moved by up to 4 % of ||X||.
// - Size. Under (29) |r| <= 1 for every mode: no mode's share of the errors grows from one step to the next, nor its
//   share of the displacement d^n = X^n - X^{n-1} (X - X^n on entry to predict), so e^{n+1} = d^{n+1} - d^n stays
//   below 2 ||d^n|| (a mode ringing at r = -1). A prediction larger than kBound = 2 times the larger of ||e^n|| and
//   ||e^{n-1}||, or than 2 ||d^n||, is refused: Newton starts from the extrapolation. It catches fits to errors that
//   are resolved but do not follow the modes (at rest, errors at the Newton tolerance, many of them earlier
//   predictions accepted as they were, are nearly dependent). On the quick §4.4 channel the predictions stay below
//   1.09 times the larger of the last two errors and 0.05 ||d^n||.
// Measured on §4.4 and on a red cell at rest (docs/time-integration.md).
// Verified by the tests GuessErrorPredictor.* (known recurrences predicted exactly, the history rules, the
// resolution and size rules, fewer fluid solves for the same JFNK steps, the cell at rest).
#include <array>
#include <cstddef>
#include <deque>
#include <limits>
#include <span>
#include <vector>

namespace immerse {

/// Predicts the error of the implicit step's extrapolated initial guess from the errors of the steps before.
class GuessErrorPredictor {
 public:
  static constexpr int kMaxTerms = 5;
  static constexpr int kWindow = 2;  ///< errors each fit is fitted to
  /// A fit uses only errors above kResolved ||X^n|| (over their block): far above the round-off of the positions.
  static constexpr double kResolved = 1e4 * std::numeric_limits<double>::epsilon();
  /// A prediction larger than kBound times the larger of the last two errors, or than kBound times the displacement
  /// of the extrapolation, is refused.
  static constexpr double kBound = 2;

  /// Adds to X, the linear extrapolation of the positions X^n (`positions`) over a step dt, the error predicted for
  /// it in each block where a recurrence holds and its prediction is trusted (the rules above; nothing elsewhere).
  /// `offsets` splits the unknowns into blocks fitted separately (block b is [offsets[b], offsets[b+1]); empty: one).
  void predict(double dt, std::span<const double> positions, std::span<double> X,
               std::span<const std::size_t> offsets = {}) const;
  /// The largest number of terms a block's prediction with these arguments uses (0: no block predicts).
  int terms(double dt, std::span<const double> positions, std::span<const double> X,
            std::span<const std::size_t> offsets = {}) const;
  /// Records the error of a step of length dt that started from the linear extrapolation.
  void record(double dt, std::span<const double> error);
  void clear();

  /// The stored errors, oldest first, concatenated (for checkpoints), and the step they belong to.
  std::vector<double> errors() const;
  double dt() const { return dt_; }
  /// The number of stored errors.
  std::size_t count() const { return e_.size(); }
  /// Replaces the history by errors() of vectors of length n recorded with step dt.
  void restore(std::span<const double> errors, std::size_t n, double dt);
  /// The same for `count` vectors, also of length 0 (a process of a distributed run that owns no membrane).
  void restore(std::span<const double> errors, std::size_t n, std::size_t count, double dt);

 private:
  static constexpr std::size_t kDepth = kMaxTerms + kWindow + 1;  // one more to recompute the last prediction
  struct Fit {
    int terms = 0;
    std::array<double, kMaxTerms> a{};
  };
  using Gram = std::array<std::array<double, kDepth>, kDepth>;
  // Brings the Gram matrices of the stored errors over each block of b up to date: each error's dot products with
  // the errors before it are computed once, when it is first needed, and kept while both stay stored (each sum in
  // the order of the unknowns, so the entries do not depend on when they were computed or on the thread count).
  void update_grams(const std::vector<std::size_t>& b) const;
  // The fit that predicts e_[m] from e_[m-1], e_[m-2], ... (m <= number stored) in a block of `unknowns`, using
  // only the errors after the last one whose squared norm is not above floor2.
  static Fit fit(const Gram& G, std::size_t m, std::size_t unknowns, double floor2);
  // The fit for the next error in a block, or none (the rules above).
  Fit next_fit(const Gram& G, std::size_t unknowns, double floor2) const;
  // next_fit for block k on its resolved errors, or none where its prediction exceeds the bounds.
  Fit trusted_fit(std::size_t k, const std::vector<std::size_t>& b, std::span<const double> positions,
                  std::span<const double> X) const;
  void check(std::span<const double> positions, std::span<const double> X) const;
  std::vector<std::size_t> blocks(std::span<const std::size_t> offsets) const;
  std::deque<std::vector<double>> e_;
  double dt_ = 0;
  mutable std::vector<std::size_t> gram_blocks_;  // the blocks grams_ belongs to
  mutable std::vector<Gram> grams_;               // per block, over e_[0 .. gram_rows_)
  mutable std::size_t gram_rows_ = 0;
};

}  // namespace immerse
