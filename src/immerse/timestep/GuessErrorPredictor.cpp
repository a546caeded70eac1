#include "immerse/timestep/GuessErrorPredictor.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "immerse/core/Cholesky_K.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/core/ThreadThresholds.hpp"

namespace immerse {

void GuessErrorPredictor::update_grams(const std::vector<std::size_t>& b) const {
  if (b != gram_blocks_) {
    gram_blocks_ = b;
    gram_rows_ = 0;
  }
  const std::size_t m = e_.size(), nblocks = b.size() - 1;
  if (gram_rows_ == m) return;
  grams_.resize(nblocks);
#pragma omp parallel for schedule(dynamic) if (nblocks > 1 && long(e_.back().size()) >= kMinValuesForThreads)
  for (std::size_t blk = 0; blk < nblocks; ++blk) {
    Gram& G = grams_[blk];
    for (std::size_t i = gram_rows_; i < m; ++i) {
      const double* const ei = e_[i].data();
      std::array<double, kDepth> row{};
      for (std::size_t j = 0; j <= i; ++j) {
        const double* const ej = e_[j].data();
        double s = 0;
        for (std::size_t k = b[blk]; k < b[blk + 1]; ++k) s += ei[k] * ej[k];
        row[j] = s;
      }
      for (std::size_t j = 0; j <= i; ++j) G[i][j] = G[j][i] = row[j];
    }
  }
  gram_rows_ = m;
}

GuessErrorPredictor::Fit GuessErrorPredictor::fit(const Gram& G, std::size_t m, std::size_t unknowns, double floor2) {
  std::size_t first = 0;  // the errors it may use: e_[first .. m), all above the floor
  for (std::size_t j = 0; j < m; ++j)
    if (!(G[j][j] > floor2)) first = j + 1;
  const std::size_t usable = m - first;
  if (usable < 2) return {};
  for (int t = static_cast<int>(std::min<std::size_t>(kMaxTerms, usable - 1)); t >= 1; --t) {
    // Normal equations of e_[j] ~ sum_p a_p e_[j-1-p] over the targets j = m-w .. m-1; more equations than terms,
    // or the fit would be exact whatever the errors.
    const std::size_t w = std::min<std::size_t>(kWindow, usable - static_cast<std::size_t>(t));
    if (w * unknowns <= static_cast<std::size_t>(t)) continue;
    std::array<double, kMaxTerms * kMaxTerms> N{};
    std::array<double, kMaxTerms> b{};
    double yy = 0;
    for (std::size_t j = m - w; j < m; ++j) {
      yy += G[j][j];
      for (int p = 0; p < t; ++p) {
        b[p] += G[j][j - 1 - p];
        for (int q = 0; q < t; ++q) N[p * kMaxTerms + q] += G[j - 1 - p][j - 1 - q];
      }
    }
    // A squared pivot below 1e-8 of its diagonal entry (the new error's sine to the span of the others below 1e-4)
    // means the errors are dependent: a term less.
    if (!cholesky_factor(N.data(), t, kMaxTerms, [](double pivot, double diagonal) { return pivot > 1e-8 * diagonal; }))
      continue;
    Fit f;
    f.terms = t;
    f.a = b;
    cholesky_solve(N.data(), t, kMaxTerms, f.a.data());
    double res = yy;  // squared residual of the fit
    for (int p = 0; p < t; ++p) res -= f.a[p] * b[p];
    return res < 0.25 * yy ? f : Fit{};  // relative residual below 1/2
  }
  return {};
}

GuessErrorPredictor::Fit GuessErrorPredictor::next_fit(const Gram& G, std::size_t unknowns, double floor2) const {
  const std::size_t m = e_.size();
  if (m >= 3) {  // did the fit one step earlier, applied to e_[m-2], e_[m-3], ..., predict e_[m-1]?
    if (const Fit last = fit(G, m - 1, unknowns, floor2); last.terms > 0) {
      const std::size_t y = m - 1;
      double miss = G[y][y];
      for (int p = 0; p < last.terms; ++p) {
        miss -= 2 * last.a[p] * G[y][y - 1 - p];
        for (int q = 0; q < last.terms; ++q) miss += last.a[p] * last.a[q] * G[y - 1 - p][y - 1 - q];
      }
      if (miss > G[y][y]) return {};
    }
  }
  return fit(G, m, unknowns, floor2);
}

GuessErrorPredictor::Fit GuessErrorPredictor::trusted_fit(std::size_t k, const std::vector<std::size_t>& b,
                                                          std::span<const double> positions,
                                                          std::span<const double> X) const {
  double xx = 0, dd = 0;  // ||X^n||^2 and the squared displacement of the extrapolation, over the block
  for (std::size_t i = b[k]; i < b[k + 1]; ++i) {
    xx += positions[i] * positions[i];
    dd += (X[i] - positions[i]) * (X[i] - positions[i]);
  }
  const Gram& G = grams_[k];
  const Fit f = next_fit(G, b[k + 1] - b[k], kResolved * kResolved * xx);
  if (f.terms == 0) return f;
  const std::size_t m = e_.size();
  double pp = 0;  // ||a1 e_[m-1] + ... + at e_[m-t]||^2
  for (int p = 0; p < f.terms; ++p)
    for (int q = 0; q < f.terms; ++q) pp += f.a[p] * f.a[q] * G[m - 1 - p][m - 1 - q];
  const double recent = std::max(G[m - 1][m - 1], G[m - 2][m - 2]);  // a fit has at least two errors
  if (pp > kBound * kBound * recent || pp > kBound * kBound * dd) return {};
  return f;
}

std::vector<std::size_t> GuessErrorPredictor::blocks(std::span<const std::size_t> offsets) const {
  const std::size_t n = e_.empty() ? 0 : e_.back().size();
  if (offsets.empty()) return {0, n};
  if (offsets.front() != 0 || offsets.back() != n || !std::ranges::is_sorted(offsets))
    throw std::logic_error("GuessErrorPredictor: the block offsets do not split the unknowns");
  return {offsets.begin(), offsets.end()};
}

void GuessErrorPredictor::check(std::span<const double> positions, std::span<const double> X) const {
  if (X.size() != e_.back().size() || positions.size() != X.size())
    throw std::logic_error("GuessErrorPredictor: the number of unknowns changed");
}

int GuessErrorPredictor::terms(double dt, std::span<const double> positions, std::span<const double> X,
                               std::span<const std::size_t> offsets) const {
  if (dt != dt_ || e_.empty()) return 0;
  check(positions, X);
  const auto b = blocks(offsets);
  update_grams(b);
  int most = 0;
  for (std::size_t k = 0; k + 1 < b.size(); ++k) most = std::max(most, trusted_fit(k, b, positions, X).terms);
  return most;
}

void GuessErrorPredictor::predict(double dt, std::span<const double> positions, std::span<double> X,
                                  std::span<const std::size_t> offsets) const {
  if (dt != dt_ || e_.empty()) return;
  check(positions, X);
  const auto b = blocks(offsets);
  update_grams(b);
  const std::size_t m = e_.size(), nblocks = b.size() - 1;
  // Blocks (membranes) in parallel, each summed in order: the prediction does not depend on the thread count.
#pragma omp parallel for schedule(dynamic) if (nblocks > 1 && long(X.size()) >= kMinValuesForThreads)
  for (std::size_t k = 0; k < nblocks; ++k) {
    const Fit f = trusted_fit(k, b, positions, X);
    for (int p = 0; p < f.terms; ++p)
      for (std::size_t i = b[k]; i < b[k + 1]; ++i) X[i] += f.a[p] * e_[m - 1 - p][i];
  }
}

void GuessErrorPredictor::record(double dt, std::span<const double> error) {
  if (dt != dt_ || (!e_.empty() && e_.back().size() != error.size())) clear();
  dt_ = dt;
  std::vector<double> v;
  if (e_.size() == kDepth) {  // the oldest error's storage takes the new one
    v = std::move(e_.front());
    e_.pop_front();
    for (Gram& G : grams_) {  // its row and column leave the Gram matrices
      for (std::size_t i = 1; i < kDepth; ++i)
        for (std::size_t j = 1; j < kDepth; ++j) G[i - 1][j - 1] = G[i][j];
    }
    gram_rows_ = gram_rows_ > 0 ? gram_rows_ - 1 : 0;
  }
  v.assign(error.begin(), error.end());
  e_.push_back(std::move(v));
}

void GuessErrorPredictor::clear() {
  e_.clear();
  dt_ = 0;
  gram_rows_ = 0;
}

std::vector<double> GuessErrorPredictor::errors() const {
  std::vector<double> out;
  for (const auto& v : e_) out.insert(out.end(), v.begin(), v.end());
  return out;
}

void GuessErrorPredictor::restore(std::span<const double> errors, std::size_t n, double dt) {
  if (!errors.empty() && (n == 0 || errors.size() % n != 0 || errors.size() / n > kDepth))
    throw InputError("checkpoint: integrator.guess_errors holds " + std::to_string(errors.size()) +
                     " values, not up to " + std::to_string(kDepth) + " vectors of " + std::to_string(n));
  restore(errors, n, errors.empty() ? 0 : errors.size() / n, dt);
}

void GuessErrorPredictor::restore(std::span<const double> errors, std::size_t n, std::size_t count, double dt) {
  if (errors.size() != count * n || count > kDepth)
    throw std::logic_error("GuessErrorPredictor::restore: " + std::to_string(errors.size()) + " values for " +
                           std::to_string(count) + " vectors of " + std::to_string(n));
  clear();
  for (std::size_t k = 0; k < count; ++k) record(dt, errors.subspan(k * n, n));
}

}  // namespace immerse
