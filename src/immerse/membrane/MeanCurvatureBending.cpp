#include "immerse/membrane/MeanCurvatureBending.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/BalancedRange.hpp"
#include "immerse/membrane/DihedralAngle_K.hpp"
#include "immerse/membrane/QuadraticTriangle_K.hpp"

namespace immerse {

namespace {

/// CSR of the slots (kSlots per item) each node appears in, ascending in item index.
template <std::size_t kSlots, class Item, class NodeOf>
void node_slots(const std::vector<Item>& items, std::size_t N, NodeOf node_of, std::vector<int>& start,
                std::vector<int>& slot) {
  start.assign(N + 1, 0);
  for (const auto& it : items)
    for (std::size_t s = 0; s < kSlots; ++s) ++start[node_of(it, s) + 1];
  for (std::size_t i = 0; i < N; ++i) start[i + 1] += start[i];
  slot.resize(kSlots * items.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (std::size_t t = 0; t < items.size(); ++t)
    for (std::size_t s = 0; s < kSlots; ++s) slot[fill[node_of(items[t], s)]++] = static_cast<int>(kSlots * t + s);
}

}  // namespace

// Scratch data of one evaluation, one per calling thread (as ElasticMembrane's).
struct MeanCurvatureBending::Work {
  std::vector<double> theta, len;      // per hinge
  std::vector<Vec3> dtheta;            // per hinge slot: dtheta/dx of i, j, k, l
  std::vector<double> tri_area;        // per flat triangle
  std::vector<Vec3> tri_unit_normal;   // per flat triangle
  std::vector<double> area, M;         // per node: A_i, M_i
  std::vector<double> alpha, beta;     // per node: dE/dM_i, dE/dA_i
  std::vector<Vec3> edge_grad, tri_grad;  // per slot: dE/dx
};

MeanCurvatureBending::Work& MeanCurvatureBending::workspace() {
  thread_local Work w;
  return w;
}

MeanCurvatureBending::MeanCurvatureBending(const Mesh& mesh, std::span<const Vec3> reference, Bending bending,
                                           bool threaded)
    : kappa_B_(bending.kappa_B), threaded_(threaded) {
  const std::size_t N = reference.size();
  tris_.reserve(4 * mesh.elements.size());
  for (const auto& el : mesh.elements)
    for (const auto& s : tri6::kSubTriangles) tris_.push_back({el[s[0]], el[s[1]], el[s[2]]});

  // Half-edges (a -> b, opposite c) sorted by undirected edge; a hinge is a pair of opposite half-edges.
  struct HalfEdge {
    int lo, hi, a, b, c, t;
  };
  std::vector<HalfEdge> half;
  half.reserve(3 * tris_.size());
  for (std::size_t t = 0; t < tris_.size(); ++t)
    for (int s = 0; s < 3; ++s) {
      const int a = tris_[t][s], b = tris_[t][(s + 1) % 3], c = tris_[t][(s + 2) % 3];
      half.push_back({std::min(a, b), std::max(a, b), a, b, c, static_cast<int>(t)});
    }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.t < y.t;
  });
  for (std::size_t h = 0; h < half.size();) {
    std::size_t n = 1;
    while (h + n < half.size() && half[h + n].lo == half[h].lo && half[h + n].hi == half[h].hi) ++n;
    const std::string where = "membrane mesh edge " + std::to_string(half[h].lo) + "-" + std::to_string(half[h].hi);
    require(n <= 2, where, static_cast<double>(n), "shared by at most two flat triangles");
    if (n == 2) {
      const HalfEdge &p = half[h], &q = half[h + 1];
      require(p.a == q.b, where, "traversed in opposite directions by its two triangles (consistent orientation)");
      edges_.push_back({p.a, p.b, p.c, q.c});
    }
    h += n;
  }
  node_slots<4>(edges_, N, [](const Hinge& e, std::size_t s) { return e.node(s); }, edge_start_, edge_slot_);
  node_slots<3>(tris_, N, [](const std::array<int, 3>& t, std::size_t s) { return t[s]; }, tri_start_, tri_slot_);

  for (std::size_t t = 0; t < tris_.size(); ++t) {
    const auto& v = tris_[t];
    const double a = norm(cross(reference[v[1]] - reference[v[0]], reference[v[2]] - reference[v[0]]));
    require(a > 0 && std::isfinite(a), "membrane reference element " + std::to_string(t / 4),
            "flat sub-triangles of non-zero area");
  }
  c_ref_.assign(N, 0.0);
  if (bending.reference == ReferenceCurvature::RestShape) {
    Work w;
    curvature(reference, w, false);
    for (std::size_t i = 0; i < N; ++i) c_ref_[i] = w.M[i] / (2 * w.area[i]);
  }
}

// theta_e, l_e (and dtheta_e/dx), the flat triangles' areas (and unit normals), A_i and M_i.
void MeanCurvatureBending::curvature(std::span<const Vec3> X, Work& w, bool with_gradient) const {
  const int H = static_cast<int>(edges_.size()), T = static_cast<int>(tris_.size());
  const int N = static_cast<int>(X.size());
  w.theta.resize(H);
  w.len.resize(H);
  if (with_gradient) w.dtheta.resize(4 * static_cast<std::size_t>(H));
  w.tri_area.resize(T);
  w.tri_unit_normal.resize(T);
  int bad = INT_MAX;
#pragma omp parallel for schedule(static) reduction(min : bad) if (threaded_)
  for (int t = 0; t < T; ++t) {
    const auto& v = tris_[t];
    const Vec3 n = cross(X[v[1]] - X[v[0]], X[v[2]] - X[v[0]]);
    const double a = norm(n);
    if (!(a > 0) || !std::isfinite(a)) bad = std::min(bad, t / 4);
    w.tri_area[t] = 0.5 * a;
    w.tri_unit_normal[t] = n * (1 / a);
  }
  if (bad != INT_MAX)
    throw SimulationError("element " + std::to_string(bad) + ": a flat sub-triangle degenerated (bending energy)");
#pragma omp parallel for schedule(static) if (threaded_)
  for (int e = 0; e < H; ++e) {
    const Hinge& h = edges_[e];
    const auto d = membrane_k::dihedral_angle(X[h.i], X[h.j], X[h.k], X[h.l]);
    w.theta[e] = d.theta;
    w.len[e] = norm(X[h.j] - X[h.i]);
    if (with_gradient)
      for (int s = 0; s < 4; ++s) w.dtheta[4 * e + s] = d.grad[s];
  }
  w.area.resize(N);
  w.M.resize(N);
#pragma omp parallel for schedule(static) if (threaded_)
  for (int i = 0; i < N; ++i) {
    double a = 0, m = 0;
    for (int j = tri_start_[i]; j < tri_start_[i + 1]; ++j) a += w.tri_area[tri_slot_[j] / 3];
    for (int j = edge_start_[i]; j < edge_start_[i + 1]; ++j)
      if (edge_slot_[j] % 4 < 2) m += w.len[edge_slot_[j] / 4] * w.theta[edge_slot_[j] / 4];
    w.area[i] = a / 3;
    w.M[i] = m;
  }
}

double MeanCurvatureBending::energy(std::span<const Vec3> X) const {
  Work& w = workspace();
  curvature(X, w, false);
  double E = 0;
  for (std::size_t i = 0; i < X.size(); ++i) {
    const double d = w.M[i] / (2 * w.area[i]) - c_ref_[i];
    E += w.area[i] * d * d;
  }
  return 0.5 * kappa_B_ * E;
}

// With d_i = M_i / (2 A_i) - 2Hbar_i:  dE/dX = sum_i alpha_i dM_i/dX + beta_i dA_i/dX,
// alpha_i = kappa_B d_i / 2, beta_i = -kappa_B d_i (d_i + 2 * 2Hbar_i) / 2;
// dM_i = sum_e (theta_e dl_e + l_e dtheta_e), dA_i = sum_t dA_t / 3, dA_t/dx_a = n_t x (x_c - x_b) / 2.
void MeanCurvatureBending::add_force(std::span<const Vec3> X, std::vector<Vec3>& F) const {
  Work& w = workspace();
  curvature(X, w, true);
  const int H = static_cast<int>(edges_.size()), T = static_cast<int>(tris_.size());
  const int N = static_cast<int>(X.size());
  w.alpha.resize(N);
  w.beta.resize(N);
  for (int i = 0; i < N; ++i) {
    const double d = w.M[i] / (2 * w.area[i]) - c_ref_[i];
    w.alpha[i] = 0.5 * kappa_B_ * d;
    w.beta[i] = -0.5 * kappa_B_ * d * (d + 2 * c_ref_[i]);
  }
  w.edge_grad.resize(4 * static_cast<std::size_t>(H));
  w.tri_grad.resize(3 * static_cast<std::size_t>(T));
#pragma omp parallel for schedule(static) if (threaded_)
  for (int e = 0; e < H; ++e) {
    const Hinge& h = edges_[e];
    const double g = w.alpha[h.i] + w.alpha[h.j];
    const Vec3 dl = (X[h.j] - X[h.i]) * (w.theta[e] / w.len[e]);  // theta_e dl_e/dx_j
    const double gl = g * w.len[e];
    w.edge_grad[4 * e] = gl * w.dtheta[4 * e] - g * dl;
    w.edge_grad[4 * e + 1] = gl * w.dtheta[4 * e + 1] + g * dl;
    w.edge_grad[4 * e + 2] = gl * w.dtheta[4 * e + 2];
    w.edge_grad[4 * e + 3] = gl * w.dtheta[4 * e + 3];
  }
#pragma omp parallel for schedule(static) if (threaded_)
  for (int t = 0; t < T; ++t) {
    const auto& v = tris_[t];
    const double b = (w.beta[v[0]] + w.beta[v[1]] + w.beta[v[2]]) * (1.0 / 6);  // beta / 3, dA_t with its 1/2
    const Vec3& n = w.tri_unit_normal[t];
    for (int s = 0; s < 3; ++s) w.tri_grad[3 * t + s] = b * cross(n, X[v[(s + 2) % 3]] - X[v[(s + 1) % 3]]);
  }
#pragma omp parallel if (threaded_)
  for (auto [i, end] = balanced_node_range(edge_start_); i < end; ++i) {
    Vec3 g;
    for (int j = edge_start_[i]; j < edge_start_[i + 1]; ++j) g += w.edge_grad[edge_slot_[j]];
    for (int j = tri_start_[i]; j < tri_start_[i + 1]; ++j) g += w.tri_grad[tri_slot_[j]];
    F[i] -= g;
  }
}

std::size_t MeanCurvatureBending::memory_bytes() const {
  const std::size_t N = c_ref_.size(), H = edges_.size(), T = tris_.size();
  const std::size_t persistent = T * sizeof(std::array<int, 3>) + H * sizeof(Hinge) +
                                 (edge_start_.size() + edge_slot_.size() + tri_start_.size() + tri_slot_.size()) *
                                     sizeof(int) +
                                 N * sizeof(double);
  const std::size_t work = H * 2 * sizeof(double) + 4 * H * sizeof(Vec3) + T * (sizeof(double) + sizeof(Vec3)) +
                           4 * N * sizeof(double) + (4 * H + 3 * T) * sizeof(Vec3);
  return persistent + work;
}

}  // namespace immerse
