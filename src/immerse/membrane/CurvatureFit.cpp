#include "immerse/membrane/CurvatureFit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include "immerse/core/Cholesky_K.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/membrane/BalancedRange.hpp"

namespace immerse {

namespace {

constexpr int kTerms = 14;  // monomials s^a t^b, 1 <= a + b <= 4

/// Monomials in scaled chart coordinates: S, T, S^2, ST, T^2, S^3, S^2T, ST^2, T^3, S^4, S^3T, S^2T^2, ST^3, T^4.
std::array<double, kTerms> monomials(double S, double T) {
  const double S2 = S * S, T2 = T * T;
  return {S, T, S2, S * T, T2, S2 * S, S2 * T, S * T2, T2 * T, S2 * S2, S2 * S * T, S2 * T2, S * T2 * T, T2 * T2};
}

}  // namespace

CurvatureFit::CurvatureFit(const Mesh& mesh, const std::vector<Vec3>& reference) {
  const int N = static_cast<int>(reference.size());
  std::vector<std::vector<int>> node_elements(N);
  for (int e = 0; e < static_cast<int>(mesh.elements.size()); ++e)
    for (int v : mesh.elements[e]) node_elements[v].push_back(e);
  start_.assign(1, 0);
  for (int i = 0; i < N; ++i) {
    // Elements incident to i, and those sharing an edge (a mid-side node) with them; their nodes but i.
    std::vector<int> elems = node_elements[i];
    for (int e : node_elements[i])
      for (int k = 3; k < 6; ++k)
        for (int f : node_elements[mesh.elements[e][k]]) elems.push_back(f);
    std::vector<int> nodes;
    Vec3 e3;
    for (int e : node_elements[i]) {
      const auto& el = mesh.elements[e];
      e3 += cross(reference[el[1]] - reference[el[0]], reference[el[2]] - reference[el[0]]);
    }
    for (int e : elems)
      for (int v : mesh.elements[e])
        if (v != i) nodes.push_back(v);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());

    // Chart: tangent plane of e3, coordinates scaled by the neighbourhood radius h.
    e3 = normalized(e3);
    const Vec3 a = std::fabs(e3.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 e1 = normalized(cross(a, e3)), e2 = cross(e3, e1);
    double h = 0;
    for (int p : nodes) h = std::max(h, norm(reference[p] - reference[i]));
    std::vector<std::array<double, kTerms>> A(nodes.size());
    std::array<double, kTerms * kTerms> M{};
    for (std::size_t r = 0; r < nodes.size(); ++r) {
      const Vec3 d = reference[nodes[r]] - reference[i];
      A[r] = monomials(dot(d, e1) / h, dot(d, e2) / h);
      for (int p = 0; p < kTerms; ++p)
        for (int q = 0; q <= p; ++q) M[p * kTerms + q] += A[r][p] * A[r][q];
    }
    for (int p = 0; p < kTerms; ++p)
      for (int q = p + 1; q < kTerms; ++q) M[p * kTerms + q] = M[q * kTerms + p];
    const bool factored = nodes.size() >= kTerms && cholesky_factor(M.data(), kTerms, kTerms, [](double pivot, double) {
                            return pivot > 1e-12;
                          });
    require(factored, "membrane mesh node " + std::to_string(i),
            "a neighbourhood that determines the quartic curvature fit (well-shaped elements around it)");
    // Row r of (A^T A)^{-1} A^T for the five derivative coefficients: solve with the unit vectors e_0..e_4
    // (the inverse is symmetric), then weights for neighbour p = (A^T A)^{-1}_{k,:} . A[p], with the chart
    // scaling and the factor 2 of the pure second derivatives folded in.
    std::array<std::array<double, kTerms>, 5> inv{};
    for (int k = 0; k < 5; ++k) {
      inv[k][k] = 1;
      cholesky_solve(M.data(), kTerms, kTerms, inv[k].data());
    }
    const std::array<double, 5> scale{1 / h, 1 / h, 2 / (h * h), 1 / (h * h), 2 / (h * h)};
    for (std::size_t r = 0; r < nodes.size(); ++r) {
      nbr_.push_back(nodes[r]);
      for (int k = 0; k < 5; ++k) {
        double s = 0;
        for (int q = 0; q < kTerms; ++q) s += inv[k][q] * A[r][q];
        weights_.push_back(scale[k] * s);
      }
    }
    start_.push_back(static_cast<int>(nbr_.size()));
  }
}

void CurvatureFit::compute(std::span<const Vec3> X, std::vector<Vec3>& normal, std::vector<Mat3>& kappa) const {
  const int N = static_cast<int>(start_.size()) - 1;
  normal.resize(N);
  kappa.resize(N);
#pragma omp parallel if (static_cast<long>(N) >= kMinElementsForThreads)
  for (auto [i, end] = balanced_node_range(start_); i < end; ++i) {
    Vec3 Xs, Xt, Xss, Xst, Xtt;
    for (int j = start_[i]; j < start_[i + 1]; ++j) {
      const Vec3 d = X[nbr_[j]] - X[i];
      const double* w = &weights_[5 * static_cast<std::size_t>(j)];
      Xs += w[0] * d;
      Xt += w[1] * d;
      Xss += w[2] * d;
      Xst += w[3] * d;
      Xtt += w[4] * d;
    }
    const Vec3 c = cross(Xs, Xt);
    const Vec3 n = c * (1 / norm(c));
    const double g11 = dot(Xs, Xs), g12 = dot(Xs, Xt), g22 = dot(Xt, Xt), r = 1 / (g11 * g22 - g12 * g12);
    const Vec3 ds = (g22 * Xs - g12 * Xt) * r, dt = (g11 * Xt - g12 * Xs) * r;
    const double b11 = dot(n, Xss), b12 = dot(n, Xst), b22 = dot(n, Xtt);
    const Mat3 st = Mat3::outer(ds, dt);
    normal[i] = n;
    kappa[i] = -1.0 * (b11 * Mat3::outer(ds, ds) + b22 * Mat3::outer(dt, dt) + b12 * (st + transpose(st)));
  }
}

}  // namespace immerse
