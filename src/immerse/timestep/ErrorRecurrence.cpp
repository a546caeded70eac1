#include "immerse/timestep/ErrorRecurrence.hpp"

#include <numeric>

#include "immerse/core/Error.hpp"

namespace immerse {
namespace {

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  return std::inner_product(a.begin(), a.end(), b.begin(), 0.0);
}

}  // namespace

ErrorRecurrence::Fit ErrorRecurrence::fit(std::size_t m) const {
  Fit best;
  if (m < 2) return best;
  const auto& y = e_[m - 1];  // fitted: e^n
  const auto& p = e_[m - 2];  // on e^{n-1}
  const double yy = dot(y, y), yp = dot(y, p), pp = dot(p, p);
  if (yy == 0 || pp == 0) return best;
  double best_res = 0.25 * yy;  // squared residual to beat: a relative residual of 1/2
  // One term: y ~ a1 p; residual^2 = yy - a1 yp.
  if (const double a1 = yp / pp, res = yy - a1 * yp; res < best_res) {
    best = {1, a1, 0};
    best_res = res;
  }
  if (m >= 3) {  // two terms: y ~ a1 p + a2 q, normal equations
    const auto& q = e_[m - 3];
    const double qq = dot(q, q), pq = dot(p, q), yq = dot(y, q);
    const double det = pp * qq - pq * pq;
    if (det > 1e-8 * pp * qq) {
      const double a1 = (yp * qq - yq * pq) / det, a2 = (yq * pp - yp * pq) / det;
      if (const double res = yy - a1 * yp - a2 * yq; res < best_res) best = {2, a1, a2};
    }
  }
  return best;
}

ErrorRecurrence::Fit ErrorRecurrence::next_fit() const {
  const std::size_t m = e_.size();
  if (m >= 3) {  // did the last prediction, e^n ~ a1 e^{n-1} + a2 e^{n-2} from the fit one step earlier, help?
    const Fit last = fit(m - 1);
    if (last.terms > 0) {
      const auto& y = e_[m - 1];
      double miss = 0, yy = 0;
      for (std::size_t i = 0; i < y.size(); ++i) {
        const double pred = last.a1 * e_[m - 2][i] + (last.terms == 2 ? last.a2 * e_[m - 3][i] : 0.0);
        miss += (y[i] - pred) * (y[i] - pred);
        yy += y[i] * y[i];
      }
      if (miss > yy) return {};
    }
  }
  return fit(m);
}

int ErrorRecurrence::terms(double dt) const { return dt == dt_ ? next_fit().terms : 0; }

void ErrorRecurrence::predict(double dt, std::span<double> X) const {
  if (dt != dt_) return;
  const Fit f = next_fit();
  if (f.terms == 0) return;
  const std::size_t m = e_.size();
  const auto& en = e_[m - 1];
  if (X.size() != en.size()) throw std::logic_error("ErrorRecurrence: the number of unknowns changed");
  for (std::size_t i = 0; i < X.size(); ++i) X[i] += f.a1 * en[i];
  if (f.terms == 2)
    for (std::size_t i = 0; i < X.size(); ++i) X[i] += f.a2 * e_[m - 2][i];
}

void ErrorRecurrence::record(double dt, std::span<const double> error) {
  if (dt != dt_ || (!e_.empty() && e_.back().size() != error.size())) clear();
  dt_ = dt;
  if (e_.size() == kDepth) e_.pop_front();
  e_.emplace_back(error.begin(), error.end());
}

void ErrorRecurrence::clear() {
  e_.clear();
  dt_ = 0;
}

std::vector<double> ErrorRecurrence::errors() const {
  std::vector<double> out;
  for (const auto& v : e_) out.insert(out.end(), v.begin(), v.end());
  return out;
}

void ErrorRecurrence::restore(std::span<const double> errors, std::size_t n, double dt) {
  if (!errors.empty() && (n == 0 || errors.size() % n != 0 || errors.size() / n > kDepth))
    throw InputError("checkpoint: integrator.guess_errors holds " + std::to_string(errors.size()) +
                     " values, not up to " + std::to_string(kDepth) + " vectors of " + std::to_string(n));
  clear();
  for (std::size_t k = 0; !errors.empty() && k < errors.size() / n; ++k) record(dt, errors.subspan(k * n, n));
}

}  // namespace immerse
