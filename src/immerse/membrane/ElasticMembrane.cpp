#include "immerse/membrane/ElasticMembrane.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>
#include <utility>

#include "immerse/core/Error.hpp"
#include "immerse/core/Mat3.hpp"
#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/membrane/BalancedRange.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MembraneKinematics_K.hpp"
#include "immerse/membrane/QuadraticTriangle_K.hpp"

namespace immerse {

namespace {

using membrane_k::Frame;
using membrane_k::Nodes;
using membrane_k::RefMetric;
using membrane_k::Tangents;

constexpr std::array<tri6::Shape, tri6::kNodes> node_shapes() {
  std::array<tri6::Shape, tri6::kNodes> s{};
  for (int k = 0; k < tri6::kNodes; ++k) s[k] = tri6::shape(tri6::kNodePoints[k].xi, tri6::kNodePoints[k].eta);
  return s;
}
constexpr std::array<tri6::Shape, tri6::kQuadPoints> quad_shapes() {
  std::array<tri6::Shape, tri6::kQuadPoints> s{};
  for (int q = 0; q < tri6::kQuadPoints; ++q) s[q] = tri6::shape(tri6::kQuad[q].xi, tri6::kQuad[q].eta);
  return s;
}
constexpr auto kNodeShape = node_shapes();
constexpr auto kQuadShape = quad_shapes();

/// Parametric derivatives at element node k of a field with values get(j) at the six nodes (38). Half of the
/// shape-function derivatives vanish at the nodes; only the non-zero terms are summed (in the order of j).
template <int k, class T, class Get>
inline void node_derivatives(const Get& get, T& d_xi, T& d_eta) {
  auto term = [&]<int j>() {
    constexpr double cx = kNodeShape[k].dxi[j], ce = kNodeShape[k].deta[j];
    if constexpr (cx != 0 || ce != 0) {
      const T v = get(j);
      if constexpr (cx != 0) d_xi += cx * v;
      if constexpr (ce != 0) d_eta += ce * v;
    }
  };
  [&]<int... j>(std::integer_sequence<int, j...>) { (term.template operator()<j>(), ...); }(
      std::make_integer_sequence<int, tri6::kNodes>{});
}

template <class T, class Get>
[[gnu::always_inline]] inline void node_derivatives(int k, const Get& get, T& d_xi, T& d_eta) {
  switch (k) {
    case 0: node_derivatives<0>(get, d_xi, d_eta); break;
    case 1: node_derivatives<1>(get, d_xi, d_eta); break;
    case 2: node_derivatives<2>(get, d_xi, d_eta); break;
    case 3: node_derivatives<3>(get, d_xi, d_eta); break;
    case 4: node_derivatives<4>(get, d_xi, d_eta); break;
    default: node_derivatives<5>(get, d_xi, d_eta); break;
  }
}

/// Edge quadrature of eq. (42) at Gauss point g: edge shape values, weight w_g and the products w_g L_j(s_g).
struct EdgePoint {
  tri6::EdgeShape s;
  double w;
  std::array<double, 3> wL;
};
constexpr std::array<EdgePoint, 3> edge_points() {
  std::array<EdgePoint, 3> p{};
  for (int g = 0; g < 3; ++g) {
    p[g].s = tri6::edge_shape(tri6::kEdgeS[g]);
    p[g].w = tri6::kEdgeW[g];
    for (int j = 0; j < 3; ++j) p[g].wL[j] = tri6::kEdgeW[g] * p[g].s.L[j];
  }
  return p;
}
constexpr auto kEdgePoints = edge_points();


Nodes element_nodes(const std::array<int, 6>& el, std::span<const Vec3> X) {
  Nodes x;
  for (int i = 0; i < tri6::kNodes; ++i) x[i] = X[el[i]];
  return x;
}

/// Jacobian signed against the element's own normal at its centroid, a_xi x a_eta at (1/3, 1/3): an inverted,
/// folded or degenerate element has a point where it is <= 0 (or not finite). The flat triangle through the three
/// vertices is no reference for a curved element: its mid-side nodes shape the surface, and on a cell's rim the
/// vertices' plane can lie 70 degrees off the surface the element describes (docs/membrane-bending.md).
[[gnu::always_inline]] inline bool jacobian_ok(const Tangents& t, const Vec3& own) {
  const double s = dot(cross(t.a_xi, t.a_eta), own);
  return s > 0 && std::isfinite(s);
}

constexpr tri6::Shape kCentroidShape = tri6::shape(1.0 / 3, 1.0 / 3);

/// a_xi x a_eta at the element's centroid.
[[gnu::always_inline]] inline Vec3 centroid_normal(const Nodes& x) {
  const Tangents t = membrane_k::tangents(x, kCentroidShape);
  return cross(t.a_xi, t.a_eta);
}

/// The Jacobian signed against the centroid normal at the six element nodes, where a curved element folds first (a
/// mid-side node past the quarter point of its edge makes it vanish at a vertex while the quadrature points still
/// see a positive one). The energy method checks these too, so that it accepts the states node_pass accepts.
[[gnu::always_inline]] inline bool element_nodes_ok(const Nodes& x, const Vec3& own) {
  for (int k = 0; k < 6; ++k) {
    Tangents t;
    node_derivatives(k, [&](int j) { return x[j]; }, t.a_xi, t.a_eta);
    if (!jacobian_ok(t, own)) return false;
  }
  return true;
}

/// Tangents at local node k of element el.
[[gnu::always_inline]] inline Tangents slot_tangents(const std::array<int, 6>& el, int k, std::span<const Vec3> X) {
  Tangents t;
  node_derivatives(k, [&](int j) { return X[el[j]]; }, t.a_xi, t.a_eta);
  return t;
}


void throw_if_bad(int bad) {
  if (bad != INT_MAX)
    throw SimulationError("element " + std::to_string(bad) +
                          ": Jacobian <= 0 or not finite (element inverted or degenerate)");
}

RefMetric load_metric(const std::vector<double>& v, std::size_t slot) {
  return {v[4 * slot], v[4 * slot + 1], v[4 * slot + 2], v[4 * slot + 3]};
}
void store_metric(std::vector<double>& v, std::size_t slot, const RefMetric& g) {
  v[4 * slot] = g.g_xx;
  v[4 * slot + 1] = g.g_xe;
  v[4 * slot + 2] = g.g_ee;
  v[4 * slot + 3] = g.J;
}

/// Share of each of the six nodes in its element: the element is cut into its four flat sub-triangles
/// (tri6::kSubTriangles) and each sub-triangle's area is split equally among its three nodes. A vertex
/// thus carries about S/12, a mid-side node about S/4; the shares sum to 1.
std::array<double, 6> lumping_fractions(const Nodes& x) {
  std::array<double, 6> f{};
  double total = 0;
  for (const auto& s : tri6::kSubTriangles) {
    const double a = norm(cross(x[s[1]] - x[s[0]], x[s[2]] - x[s[0]]));
    for (int k : s) f[k] += a;
    total += 3 * a;
  }
  const double r = 1 / total;
  for (double& v : f) v *= r;
  return f;
}

Mat3 projector(const Vec3& n) { return Mat3::identity() - Mat3::outer(n, n); }

}  // namespace

// Scratch data of one compute_force. compute_force keeps one per calling thread (workspace()), so repeated calls
// neither allocate nor zero-fill (a serial, memory-bound step) and concurrent calls from different threads stay
// independent. Every entry a pass reads was written earlier in the same call.
struct ElasticMembrane::Work {
  std::vector<membrane_k::SymTensor> node_tau;  // tension (18) averaged at nodes
  std::vector<Vec3> slot_n;                     // unit normal at each element node (6 e + k)
  std::vector<membrane_k::SymTensor> slot_tau;  // tension (18) at each element node
  std::vector<Vec3> node_n;                     // unit normal at nodes
  std::vector<Vec3> node_nfit;                  // fitted unit normal N at nodes (bending)
  std::vector<Mat3> node_kappa;                 // fitted curvature tensor (40) at nodes (bending)
  std::vector<Mat3> node_m;                     // moments (25)
  std::vector<Vec3> node_q;                     // transverse shear tension (27)
  std::vector<Vec3> el_force;                   // F_e of eq. (42) per element
  std::vector<std::array<double, 6>> el_frac;   // lumping fractions per element
  std::vector<Vec3> en_force;                   // energy method: each element's force on each of its nodes
};

ElasticMembrane::Work& ElasticMembrane::workspace() {
  thread_local Work w;
  return w;
}

ElasticMembrane::ElasticMembrane(const Mesh& mesh, std::vector<Vec3> reference, MaterialLaw law, Bending bending,
                                 ForceMethod method, ConstraintModuli constraint)
    : elements_(mesh.elements), reference_(std::move(reference)), law_(std::move(law)), bending_(bending),
      method_(method) {
  const std::size_t N = reference_.size(), E = elements_.size();
  require(N == mesh.nodes.size(), "membrane reference node count", static_cast<double>(N),
          "equal to the mesh node count " + std::to_string(mesh.nodes.size()));
  require(E > 0, "membrane mesh elements", "non-empty");
  require(bending_.kappa_B >= 0 && std::isfinite(bending_.kappa_B), "membrane.bending.kappa_B", bending_.kappa_B,
          "finite and >= 0");
  for (std::size_t e = 0; e < E; ++e)
    for (int k = 0; k < 6; ++k)
      require(elements_[e][k] >= 0 && static_cast<std::size_t>(elements_[e][k]) < N,
              "membrane mesh element " + std::to_string(e) + " node " + std::to_string(k), elements_[e][k],
              "a node index in [0, " + std::to_string(N) + ")");

  // Node -> element-node incidence (CSR), ascending in element index so every gather has a fixed order.
  inc_start_.assign(N + 1, 0);
  for (const auto& el : elements_)
    for (int v : el) ++inc_start_[v + 1];
  for (std::size_t i = 0; i < N; ++i) {
    require(inc_start_[i + 1] > 0, "membrane mesh node " + std::to_string(i), "used by at least one element");
    inc_start_[i + 1] += inc_start_[i];
  }
  inc_.resize(6 * E);
  std::vector<int> fill(inc_start_.begin(), inc_start_.end() - 1);
  for (std::size_t e = 0; e < E; ++e)
    for (int k = 0; k < 6; ++k) inc_[fill[elements_[e][k]]++] = static_cast<int>(6 * e + k);

  ref_element_area_ = element_areas(mesh, reference_);
  // Reference metric at the element nodes (contour method, node_strain) and quadrature points (energy method).
  ref_node_.resize(4 * 6 * E);
  ref_quad_.resize(4 * tri6::kQuadPoints * E);
  for (std::size_t e = 0; e < E; ++e) {
    const Nodes x = element_nodes(elements_[e], reference_);
    const Vec3 own = centroid_normal(x);
    for (int k = 0; k < 6; ++k) {
      const Tangents t = membrane_k::tangents(x, kNodeShape[k]);
      const Tangents tq = membrane_k::tangents(x, kQuadShape[k]);
      require(jacobian_ok(t, own) && jacobian_ok(tq, own), "membrane reference element " + std::to_string(e),
              "non-degenerate and counter-clockwise seen from outside (Jacobian > 0)");
      store_metric(ref_node_, 6 * e + k, membrane_k::ref_metric(t));
      store_metric(ref_quad_, 6 * e + k, membrane_k::ref_metric(tq));
    }
  }
  threaded_ = static_cast<long>(E) >= kMinElementsForThreads;
  if (bending_.kappa_B > 0) bending_energy_.emplace(mesh, reference_, bending_, threaded_);
  if (bending_.kappa_B > 0 && method_ == ForceMethod::Contour) fit_.emplace(mesh, reference_);
  kappa_ref_ = fit_ && bending_.reference == ReferenceCurvature::RestShape ? reference_mean_curvature()
                                                                          : std::vector<double>(N, 0.0);
  if (constraint.volume != 0 || constraint.area != 0) constraint_.emplace(mesh, mesh.nodes, constraint);
}

void ElasticMembrane::check_size(std::span<const Vec3> X) const {
  require(X.size() == reference_.size(), "membrane position count", static_cast<double>(X.size()),
          "equal to the node count " + std::to_string(reference_.size()));
}

// Node passes. A node's value is the mean over its element-node slots (ascending element order) of a quantity
// evaluated at that element node, and the result does not depend on the thread count.

// Normal n and (optionally) tension (17)-(20), (18) from (39) at each element node, averaged at the nodes. The
// element-node values are computed element by element (an element's six nodes gathered once, its centroid normal
// once) into per-slot arrays, then averaged node by node.
void ElasticMembrane::node_pass(std::span<const Vec3> X, bool with_tension, Work& w) const {
  const int N = static_cast<int>(num_nodes()), E = static_cast<int>(num_elements());
  w.slot_n.resize(6 * static_cast<std::size_t>(E));
  if (with_tension) w.slot_tau.resize(6 * static_cast<std::size_t>(E));
  int bad = INT_MAX;
  std::visit(
      [&](const auto& W) {
#pragma omp parallel for schedule(static) reduction(min : bad) if (threaded_)
        for (int e = 0; e < E; ++e) {
          const Nodes x = element_nodes(elements_[e], X);
          const Vec3 own = centroid_normal(x);
          for (int k = 0; k < 6; ++k) {
            const int slot = 6 * e + k;
            Tangents t;
            node_derivatives(k, [&](int j) { return x[j]; }, t.a_xi, t.a_eta);
            const Vec3 c = cross(t.a_xi, t.a_eta);  // J n, as in membrane_k::frame (dual basis not needed here)
            if (!jacobian_ok(t, own)) {
              bad = std::min(bad, e);
              break;
            }
            const double J = norm(c);
            const Vec3 nk = c * (1 / J);
            w.slot_n[slot] = nk;
            if (!with_tension) continue;
            const RefMetric g = load_metric(ref_node_, slot);
            const double r = J / g.J;  // e^{A1} (19)
            w.slot_tau[slot] = membrane_k::tension(W.at_area_ratio(r, membrane_k::second_invariant(t, g)), 1 / r,
                                                   membrane_k::left_cauchy_green(t, g), nk);
          }
        }
      },
      law_);
  throw_if_bad(bad);
  w.node_n.resize(N);
  if (with_tension) w.node_tau.resize(N);
#pragma omp parallel if (threaded_)
  for (auto [i, end] = balanced_node_range(inc_start_); i < end; ++i) {
    Vec3 n;
    membrane_k::SymTensor tau;
    for (int j = inc_start_[i]; j < inc_start_[i + 1]; ++j) {
      n += w.slot_n[inc_[j]];
      if (with_tension) tau += w.slot_tau[inc_[j]];
    }
    w.node_n[i] = normalized(n);
    if (with_tension) {
      tau *= 1.0 / (inc_start_[i + 1] - inc_start_[i]);
      w.node_tau[i] = tau;
    }
  }
}

// Bending moments (25), m = kappa_B (kappa - kappa_m^R P), P = I - N N, with the nodal normal N and curvature
// tensor kappa (40) from the local quartic fit (CurvatureFit).
void ElasticMembrane::moment_pass(std::span<const Vec3> X, Work& w) const {
  const int N = static_cast<int>(num_nodes());
  fit_->compute(X, w.node_nfit, w.node_kappa);
  w.node_m.resize(N);
#pragma omp parallel for schedule(static) if (threaded_)
  for (int i = 0; i < N; ++i)
    w.node_m[i] = bending_.kappa_B * (w.node_kappa[i] - kappa_ref_[i] * projector(w.node_nfit[i]));
}

// Bending: moments (25) at the nodes; (P.grad).m = tr K (41) at element nodes from the interpolated nodal
// moments, averaged; q (27) at nodes with the fitted normal's projector.
void ElasticMembrane::bending_passes(std::span<const Vec3> X, Work& w) const {
  const int N = static_cast<int>(num_nodes());
  moment_pass(X, w);
  w.node_q.resize(N);
#pragma omp parallel if (threaded_)
  for (auto [i, end] = balanced_node_range(inc_start_); i < end; ++i) {
    Vec3 div;
    for (int j = inc_start_[i]; j < inc_start_[i + 1]; ++j) {
      const int slot = inc_[j], e = slot / 6, k = slot % 6;
      const auto& el = elements_[e];
      const Frame f = membrane_k::frame(slot_tangents(el, k, X));
      Mat3 dm_dxi, dm_deta;
      node_derivatives(k, [&](int m) { return w.node_m[el[m]]; }, dm_dxi, dm_deta);
      div += membrane_k::moment_divergence(f, dm_dxi, dm_deta);
    }
    div *= 1.0 / (inc_start_[i + 1] - inc_start_[i]);
    w.node_q[i] = div * projector(w.node_nfit[i]);
  }
}

// Eq. (42): F_e = S_e fbar_e = oint [b.tau + (b.q) n] dl, b dl = (dX/ds x n) ds along each curved edge, with
// tau, q, n interpolated quadratically from the nodal values. The tension part is linear in the nodal tau:
// sum_g w_g tau(s_g) b_g = sum_j tau_j beta_j, beta_j = sum_g w_g L_j(s_g) b_g, accumulated per element node.
void ElasticMembrane::contour_forces(std::span<const Vec3> X, bool with_tension, bool with_bending,
                                     Work& w) const {
  const int E = static_cast<int>(num_elements());
  w.el_force.resize(E);
  w.el_frac.resize(E);
#pragma omp parallel for schedule(static) if (threaded_)
  for (int e = 0; e < E; ++e) {
    const auto& el = elements_[e];
    const Nodes x = element_nodes(el, X);
    std::array<Vec3, 6> beta{};
    Vec3 Fe;
    for (const auto& edge : tri6::kEdges)
      for (const EdgePoint& p : kEdgePoints) {
        Vec3 dX, n;
        for (int j = 0; j < 3; ++j) {
          dX += p.s.dL[j] * x[edge[j]];
          n += p.s.L[j] * w.node_n[el[edge[j]]];
        }
        n *= 1 / norm(n);
        const Vec3 b = cross(dX, n);
        if (with_tension)
          for (int j = 0; j < 3; ++j) beta[edge[j]] += p.wL[j] * b;
        if (with_bending) {
          Vec3 q;
          for (int j = 0; j < 3; ++j) q += p.s.L[j] * w.node_q[el[edge[j]]];
          Fe += (p.w * dot(b, q)) * n;
        }
      }
    if (with_tension)
      for (int k = 0; k < 6; ++k) Fe += w.node_tau[el[k]] * beta[k];
    w.el_force[e] = Fe;
    w.el_frac[e] = lumping_fractions(x);
  }
}

// F_i = -dE/dX_i = -sum_gp Jbar w (dN_i/dxi dW/da_xi + dN_i/deta dW/da_eta)   (see MembraneKinematics_K.hpp)
void ElasticMembrane::energy_forces(std::span<const Vec3> X, Work& w) const {
  const int E = static_cast<int>(num_elements());
  w.en_force.resize(6 * E);
  int bad = INT_MAX;
  std::visit(
      [&](const auto& W) {
#pragma omp parallel for schedule(static) reduction(min : bad) if (threaded_)
        for (int e = 0; e < E; ++e) {
          const Nodes x = element_nodes(elements_[e], X);
          const Vec3 own = centroid_normal(x);
          if (!element_nodes_ok(x, own)) {
            bad = std::min(bad, e);
            continue;
          }
          std::array<Vec3, 6> f{};
          for (int q = 0; q < tri6::kQuadPoints; ++q) {
            const tri6::Shape& s = kQuadShape[q];
            const Tangents t = membrane_k::tangents(x, s);
            if (!jacobian_ok(t, own)) {
              bad = std::min(bad, e);
              break;
            }
            const Frame fr = membrane_k::frame(t);
            const RefMetric g = load_metric(ref_quad_, 6 * e + q);
            const EnergyDensity d = W.at_area_ratio(fr.J / g.J, membrane_k::second_invariant(t, g));
            const auto dW = membrane_k::energy_gradient(d, t, fr, g);
            const double jw = g.J * tri6::kQuad[q].w;
            for (int i = 0; i < 6; ++i) f[i] -= jw * (s.dxi[i] * dW.d_xi + s.deta[i] * dW.d_eta);
          }
          for (int i = 0; i < 6; ++i) w.en_force[6 * e + i] = f[i];
        }
      },
      law_);
  throw_if_bad(bad);
}

void ElasticMembrane::compute_force(std::span<const Vec3> X, std::vector<Vec3>& F) const {
  check_size(X);
  Work& w = workspace();
  const bool energy = method_ == ForceMethod::Energy;
  const bool bending = bending_.kappa_B > 0;
  if (energy) {
    energy_forces(X, w);
  } else {
    node_pass(X, true, w);
    if (bending) bending_passes(X, w);
    contour_forces(X, true, bending, w);
  }
  // Node i collects its share of every element's force, slots in ascending element order.
  const int N = static_cast<int>(num_nodes());
  F.resize(N);
#pragma omp parallel if (threaded_)
  for (auto [i, end] = balanced_node_range(inc_start_); i < end; ++i) {
    Vec3 s;
    for (int j = inc_start_[i]; j < inc_start_[i + 1]; ++j) {
      const int slot = inc_[j], e = slot / 6, k = slot % 6;
      s += energy ? w.en_force[slot] : w.el_frac[e][k] * w.el_force[e];
    }
    F[i] = s;
  }
  if (energy && bending) bending_energy_->add_force(X, F);
  if (constraint_) constraint_->add_force(X, F);
}

MembraneEnergy ElasticMembrane::energy_parts(std::span<const Vec3> X) const {
  MembraneEnergy e;
  e.elastic = compute_energy(X);
  if (bending_energy_) e.bending = bending_energy_->energy(X);
  if (constraint_) e.constraint = constraint_->energy(X);
  return e;
}


double ElasticMembrane::compute_energy(std::span<const Vec3> X) const {
  check_size(X);
  const int E = static_cast<int>(num_elements());
  std::vector<double> energy(E);
  int bad = INT_MAX;
  std::visit(
      [&](const auto& W) {
#pragma omp parallel for schedule(static) reduction(min : bad) if (threaded_)
        for (int e = 0; e < E; ++e) {
          const Nodes x = element_nodes(elements_[e], X);
          const Vec3 own = centroid_normal(x);
          double s = 0;
          for (int q = 0; q < tri6::kQuadPoints; ++q) {
            const Tangents t = membrane_k::tangents(x, kQuadShape[q]);
            if (!jacobian_ok(t, own)) {
              bad = std::min(bad, e);
              break;
            }
            const RefMetric g = load_metric(ref_quad_, 6 * e + q);
            const auto inv = membrane_k::invariants(t, membrane_k::frame(t).J, g);
            s += W(inv.A1, inv.A2).W * g.J * tri6::kQuad[q].w;
          }
          energy[e] = s;
        }
      },
      law_);
  throw_if_bad(bad);
  double total = 0;
  for (double v : energy) total += v;
  return total;
}

std::vector<NodeStrain> ElasticMembrane::node_strain(std::span<const Vec3> X) const {
  check_size(X);
  const int E = static_cast<int>(num_elements());
  std::vector<Vec3> en_inv(6 * E);  // (A1, A2, (lambda1^2 - lambda2^2)/2) per element node
  int bad = INT_MAX;
#pragma omp parallel for schedule(static) reduction(min : bad) if (threaded_)
  for (int e = 0; e < E; ++e) {
    const Nodes x = element_nodes(elements_[e], X);
    const Vec3 own = centroid_normal(x);
    for (int k = 0; k < 6; ++k) {
      const Tangents t = membrane_k::tangents(x, kNodeShape[k]);
      if (!jacobian_ok(t, own)) bad = std::min(bad, e);
      const RefMetric g = load_metric(ref_node_, 6 * e + k);
      const auto inv = membrane_k::invariants(t, membrane_k::frame(t).J, g);
      en_inv[6 * e + k] = {inv.A1, inv.A2, membrane_k::principal_half_difference(t, g)};
    }
  }
  throw_if_bad(bad);
  std::vector<NodeStrain> out(num_nodes());
  for (std::size_t i = 0; i < out.size(); ++i) {
    Vec3 inv;  // mean over the node's element-node slots
    for (int j = inc_start_[i]; j < inc_start_[i + 1]; ++j) inv += en_inv[inc_[j]];
    inv *= 1.0 / (inc_start_[i + 1] - inc_start_[i]);
    const double A1 = inv.x, A2 = inv.y;
    // lambda_k^2 = A2 + 1 +- r; (18) in principal axes: tau_k = e^{-A1} (dW/dA1 + dW/dA2 lambda_k^2).
    const double s = A2 + 1, p = std::exp(A1), r = inv.z;
    const EnergyDensity d = energy_density(law_, A1, A2);
    out[i] = {A1, A2, std::sqrt(s + r), std::sqrt(std::max(0.0, s - r)), (d.dW_dA1 + d.dW_dA2 * (s + r)) / p,
              (d.dW_dA1 + d.dW_dA2 * (s - r)) / p};
  }
  return out;
}

std::vector<double> ElasticMembrane::node_area(std::span<const Vec3> X) const {
  check_size(X);
  const int E = static_cast<int>(num_elements());
  std::vector<double> S(E);
  std::vector<std::array<double, 6>> frac(E);
#pragma omp parallel for schedule(static) if (threaded_)
  for (int e = 0; e < E; ++e) {
    const Nodes x = element_nodes(elements_[e], X);
    double s = 0;
    for (int q = 0; q < tri6::kQuadPoints; ++q)
      s += membrane_k::frame(membrane_k::tangents(x, kQuadShape[q])).J * tri6::kQuad[q].w;
    S[e] = s;
    frac[e] = lumping_fractions(x);
  }
  std::vector<double> a(num_nodes());
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int j = inc_start_[i]; j < inc_start_[i + 1]; ++j) a[i] += frac[inc_[j] / 6][inc_[j] % 6] * S[inc_[j] / 6];
  return a;
}

std::vector<Vec3> ElasticMembrane::node_normal(std::span<const Vec3> X) const {
  check_size(X);
  Work w;
  node_pass(X, false, w);
  return w.node_n;
}

// kappa_m^R = tr(kappa)/2 of the reference shape, kappa from (40) averaged at the nodes.
std::vector<double> ElasticMembrane::reference_mean_curvature() const {
  std::vector<Vec3> normal;
  std::vector<Mat3> kappa;
  fit_->compute(reference_, normal, kappa);
  std::vector<double> c(num_nodes());
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = 0.5 * trace(kappa[i]);
  return c;
}

std::size_t ElasticMembrane::memory_bytes() const {
  const std::size_t N = num_nodes(), E = num_elements();
  const std::size_t persistent = E * sizeof(std::array<int, 6>) + N * sizeof(Vec3) +
                                 (inc_start_.size() + inc_.size()) * sizeof(int) +
                                 (ref_node_.size() + ref_quad_.size() + kappa_ref_.size()) * sizeof(double) +
                                 (fit_ ? fit_->memory_bytes() : 0) + (constraint_ ? constraint_->memory_bytes() : 0);
  // Workspace of compute_force (kept per calling thread): per node and per element node n, and tau (eq. 42
  // tension) or N, kappa, m and q (bending); per element F_e and the lumping fractions (eq. 42); the energy
  // method's per-element-node forces.
  const bool energy = method_ == ForceMethod::Energy, fit = fit_.has_value();
  const std::size_t work = (energy ? 6 * E * sizeof(Vec3)
                                   : (N + 6 * E) * (sizeof(Vec3) + sizeof(membrane_k::SymTensor)) +
                                         E * (sizeof(Vec3) + sizeof(std::array<double, 6>))) +
                           (fit ? N * 2 * (sizeof(Mat3) + sizeof(Vec3)) : 0);
  return persistent + work + (bending_energy_ ? bending_energy_->memory_bytes() : 0);
}

}  // namespace immerse
