#include "immerse/membrane/ElasticMembrane.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/core/Mat3.hpp"
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

Nodes element_nodes(const std::array<int, 6>& el, const std::vector<Vec3>& X) {
  Nodes x;
  for (int i = 0; i < tri6::kNodes; ++i) x[i] = X[el[i]];
  return x;
}

/// Jacobian signed against the element's chord normal (x1 - x0) x (x2 - x0): an inverted, folded or
/// degenerate element has a point where it is <= 0 (or not finite).
bool jacobian_ok(const Tangents& t, const Vec3& chord) {
  const double s = dot(cross(t.a_xi, t.a_eta), chord);
  return s > 0 && std::isfinite(s);
}

Vec3 chord_normal(const Nodes& x) { return cross(x[1] - x[0], x[2] - x[0]); }

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
  for (double& v : f) v /= total;
  return f;
}

Mat3 projector(const Vec3& n) { return Mat3::identity() - Mat3::outer(n, n); }

}  // namespace

struct ElasticMembrane::Work {
  std::vector<Mat3> en_tau, node_tau;      // tension (18) at element nodes / averaged at nodes
  std::vector<Vec3> en_n, node_n;          // unit normal
  std::vector<Mat3> en_kappa, node_kappa;  // curvature (40)
  std::vector<Mat3> node_m;                // moments (25)
  std::vector<Vec3> en_div, node_q;        // (P.grad).m from (41); transverse shear tension (27)
  std::vector<Vec3> en_force;              // each element's force on each of its nodes
};

ElasticMembrane::ElasticMembrane(const Mesh& mesh, std::vector<Vec3> reference, MaterialLaw law, Bending bending,
                                 ForceMethod method)
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

  // Reference metric at the element nodes (contour method, node_strain) and quadrature points (energy method).
  ref_node_.resize(4 * 6 * E);
  ref_quad_.resize(4 * tri6::kQuadPoints * E);
  for (std::size_t e = 0; e < E; ++e) {
    const Nodes x = element_nodes(elements_[e], reference_);
    const Vec3 chord = chord_normal(x);
    for (int k = 0; k < 6; ++k) {
      const Tangents t = membrane_k::tangents(x, kNodeShape[k]);
      const Tangents tq = membrane_k::tangents(x, kQuadShape[k]);
      require(jacobian_ok(t, chord) && jacobian_ok(tq, chord), "membrane reference element " + std::to_string(e),
              "non-degenerate and counter-clockwise seen from outside (Jacobian > 0)");
      store_metric(ref_node_, 6 * e + k, membrane_k::ref_metric(t));
      store_metric(ref_quad_, 6 * e + k, membrane_k::ref_metric(tq));
    }
  }
  kappa_ref_ = bending_.reference == ReferenceCurvature::RestShape ? reference_mean_curvature()
                                                                   : std::vector<double>(N, 0.0);
}

void ElasticMembrane::check_size(const std::vector<Vec3>& X) const {
  require(X.size() == reference_.size(), "membrane position count", static_cast<double>(X.size()),
          "equal to the node count " + std::to_string(reference_.size()));
}

namespace {

/// The surface derivative of a nodal field g at every element node, as eqs. (40) and (41) need it:
/// out[6e + k] = op(frame at node k of element e, dg/dxi, dg/deta), with g interpolated by the shape functions (38).
template <class T, class Op>
void element_node_derivative(const std::vector<std::array<int, 6>>& elements, const std::vector<Vec3>& X,
                             const std::vector<T>& g, Op op, std::vector<decltype(op(Frame{}, T{}, T{}))>& out) {
  const int E = static_cast<int>(elements.size());
  out.resize(6 * static_cast<std::size_t>(E));
#pragma omp parallel for schedule(static)
  for (int e = 0; e < E; ++e) {
    const auto& el = elements[e];
    const Nodes x = element_nodes(el, X);
    for (int k = 0; k < 6; ++k) {
      const tri6::Shape& s = kNodeShape[k];
      const Frame f = membrane_k::frame(membrane_k::tangents(x, s));
      T dg_dxi{}, dg_deta{};
      for (int j = 0; j < 6; ++j) {
        dg_dxi += s.dxi[j] * g[el[j]];
        dg_deta += s.deta[j] * g[el[j]];
      }
      out[6 * e + k] = op(f, dg_dxi, dg_deta);
    }
  }
}

/// node[i] = mean over the element-node slots of node i (fixed order).
template <class T>
void average(const std::vector<int>& start, const std::vector<int>& inc, const std::vector<T>& en,
             std::vector<T>& node) {
  const int N = static_cast<int>(start.size()) - 1;
  node.resize(N);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < N; ++i) {
    T s{};
    for (int j = start[i]; j < start[i + 1]; ++j) s += en[inc[j]];
    s *= 1.0 / (start[i + 1] - start[i]);
    node[i] = s;
  }
}

}  // namespace

void ElasticMembrane::gather(const std::vector<Vec3>& en, std::vector<Vec3>& node) const {
  const int N = static_cast<int>(num_nodes());
  node.resize(N);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < N; ++i) {
    Vec3 s{};
    for (int j = inc_start_[i]; j < inc_start_[i + 1]; ++j) s += en[inc_[j]];
    node[i] = s;
  }
}

// Element nodes: normal n and (optionally) tension (17)-(20), (18) from (39); then averaged at the nodes.
void ElasticMembrane::element_node_pass(const std::vector<Vec3>& X, bool with_tension, Work& w) const {
  const int E = static_cast<int>(num_elements());
  w.en_n.resize(6 * E);
  if (with_tension) w.en_tau.resize(6 * E);
  int bad = INT_MAX;
  std::visit(
      [&](const auto& W) {
#pragma omp parallel for schedule(static) reduction(min : bad)
        for (int e = 0; e < E; ++e) {
          const Nodes x = element_nodes(elements_[e], X);
          const Vec3 chord = chord_normal(x);
          for (int k = 0; k < 6; ++k) {
            const Tangents t = membrane_k::tangents(x, kNodeShape[k]);
            if (!jacobian_ok(t, chord)) {
              bad = std::min(bad, e);
              break;
            }
            const Frame f = membrane_k::frame(t);
            w.en_n[6 * e + k] = f.n;
            if (!with_tension) continue;
            const RefMetric g = load_metric(ref_node_, 6 * e + k);
            const auto inv = membrane_k::invariants(t, f.J, g);
            w.en_tau[6 * e + k] =
                membrane_k::tension(W(inv.A1, inv.A2), inv.A1, membrane_k::left_cauchy_green(t, g), f.n);
          }
        }
      },
      law_);
  throw_if_bad(bad);
  if (with_tension) average(inc_start_, inc_, w.en_tau, w.node_tau);
  average(inc_start_, inc_, w.en_n, w.node_n);
  for (Vec3& n : w.node_n) n = normalized(n);
}

// Curvature tensor (40) at element nodes from the interpolated nodal normals, averaged at the nodes.
void ElasticMembrane::curvature_pass(const std::vector<Vec3>& X, Work& w) const {
  element_node_derivative(elements_, X, w.node_n, membrane_k::curvature, w.en_kappa);
  average(inc_start_, inc_, w.en_kappa, w.node_kappa);
}

// Bending: kappa (40) averaged at nodes; m (25) at nodes; (P.grad).m = tr K (41) at element nodes from the
// interpolated nodal moments, averaged; q (27) at nodes.
void ElasticMembrane::bending_passes(const std::vector<Vec3>& X, Work& w) const {
  const int N = static_cast<int>(num_nodes());
  curvature_pass(X, w);

  w.node_m.resize(N);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < N; ++i)
    w.node_m[i] = bending_.kappa_B * (w.node_kappa[i] - kappa_ref_[i] * projector(w.node_n[i]));

  element_node_derivative(elements_, X, w.node_m, membrane_k::moment_divergence, w.en_div);
  average(inc_start_, inc_, w.en_div, w.node_q);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < N; ++i) w.node_q[i] = w.node_q[i] * projector(w.node_n[i]);
}

// Eq. (42): F_e = S_e fbar_e = oint [b.tau + (b.q) n] dl, b dl = (dX/ds x n) ds along each curved edge,
// with tau, q, n interpolated quadratically from the nodal values; then shared among the element's nodes.
void ElasticMembrane::contour_forces(const std::vector<Vec3>& X, bool with_tension, bool with_bending,
                                     Work& w) const {
  const int E = static_cast<int>(num_elements());
  w.en_force.resize(6 * E);
  const bool accumulate = method_ == ForceMethod::Energy;
#pragma omp parallel for schedule(static)
  for (int e = 0; e < E; ++e) {
    const auto& el = elements_[e];
    const Nodes x = element_nodes(el, X);
    Vec3 Fe;
    for (const auto& edge : tri6::kEdges)
      for (int g = 0; g < 3; ++g) {
        const tri6::EdgeShape es = tri6::edge_shape(tri6::kEdgeS[g]);
        Vec3 dX, n;
        for (int j = 0; j < 3; ++j) {
          dX += es.dL[j] * x[edge[j]];
          n += es.L[j] * w.node_n[el[edge[j]]];
        }
        n = normalized(n);
        const Vec3 b = cross(dX, n);
        Vec3 c;
        if (with_tension) {
          Mat3 tau;
          for (int j = 0; j < 3; ++j) tau += es.L[j] * w.node_tau[el[edge[j]]];
          c += tau * b;
        }
        if (with_bending) {
          Vec3 q;
          for (int j = 0; j < 3; ++j) q += es.L[j] * w.node_q[el[edge[j]]];
          c += dot(b, q) * n;
        }
        Fe += tri6::kEdgeW[g] * c;
      }
    const auto frac = lumping_fractions(x);
    for (int k = 0; k < 6; ++k) {
      if (accumulate)
        w.en_force[6 * e + k] += frac[k] * Fe;
      else
        w.en_force[6 * e + k] = frac[k] * Fe;
    }
  }
}

// F_i = -dE/dX_i = -sum_gp Jbar w (dN_i/dxi dW/da_xi + dN_i/deta dW/da_eta)   (see MembraneKinematics_K.hpp)
void ElasticMembrane::energy_forces(const std::vector<Vec3>& X, Work& w) const {
  const int E = static_cast<int>(num_elements());
  w.en_force.resize(6 * E);
  int bad = INT_MAX;
  std::visit(
      [&](const auto& W) {
#pragma omp parallel for schedule(static) reduction(min : bad)
        for (int e = 0; e < E; ++e) {
          const Nodes x = element_nodes(elements_[e], X);
          const Vec3 chord = chord_normal(x);
          std::array<Vec3, 6> f{};
          for (int q = 0; q < tri6::kQuadPoints; ++q) {
            const tri6::Shape& s = kQuadShape[q];
            const Tangents t = membrane_k::tangents(x, s);
            if (!jacobian_ok(t, chord)) {
              bad = std::min(bad, e);
              break;
            }
            const Frame fr = membrane_k::frame(t);
            const RefMetric g = load_metric(ref_quad_, 6 * e + q);
            const auto inv = membrane_k::invariants(t, fr.J, g);
            const auto dW = membrane_k::energy_gradient(W(inv.A1, inv.A2), t, fr, g);
            const double jw = g.J * tri6::kQuad[q].w;
            for (int i = 0; i < 6; ++i) f[i] -= jw * (s.dxi[i] * dW.d_xi + s.deta[i] * dW.d_eta);
          }
          for (int i = 0; i < 6; ++i) w.en_force[6 * e + i] = f[i];
        }
      },
      law_);
  throw_if_bad(bad);
}

void ElasticMembrane::compute_force(const std::vector<Vec3>& X, std::vector<Vec3>& F) const {
  check_size(X);
  Work w;
  const bool tension_by_contour = method_ == ForceMethod::Contour;
  const bool bending = bending_.kappa_B > 0;
  if (method_ == ForceMethod::Energy) energy_forces(X, w);
  if (tension_by_contour || bending) {
    element_node_pass(X, tension_by_contour, w);
    if (bending) bending_passes(X, w);
    contour_forces(X, tension_by_contour, bending, w);
  }
  gather(w.en_force, F);
}

double ElasticMembrane::compute_energy(const std::vector<Vec3>& X) const {
  check_size(X);
  const int E = static_cast<int>(num_elements());
  std::vector<double> energy(E);
  int bad = INT_MAX;
  std::visit(
      [&](const auto& W) {
#pragma omp parallel for schedule(static) reduction(min : bad)
        for (int e = 0; e < E; ++e) {
          const Nodes x = element_nodes(elements_[e], X);
          const Vec3 chord = chord_normal(x);
          double s = 0;
          for (int q = 0; q < tri6::kQuadPoints; ++q) {
            const Tangents t = membrane_k::tangents(x, kQuadShape[q]);
            if (!jacobian_ok(t, chord)) {
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

std::vector<NodeStrain> ElasticMembrane::node_strain(const std::vector<Vec3>& X) const {
  check_size(X);
  const int E = static_cast<int>(num_elements());
  std::vector<Vec3> en_inv(6 * E);  // (A1, A2, (lambda1^2 - lambda2^2)/2) per element node
  int bad = INT_MAX;
#pragma omp parallel for schedule(static) reduction(min : bad)
  for (int e = 0; e < E; ++e) {
    const Nodes x = element_nodes(elements_[e], X);
    const Vec3 chord = chord_normal(x);
    for (int k = 0; k < 6; ++k) {
      const Tangents t = membrane_k::tangents(x, kNodeShape[k]);
      if (!jacobian_ok(t, chord)) bad = std::min(bad, e);
      const RefMetric g = load_metric(ref_node_, 6 * e + k);
      const auto inv = membrane_k::invariants(t, membrane_k::frame(t).J, g);
      en_inv[6 * e + k] = {inv.A1, inv.A2, membrane_k::principal_half_difference(t, g)};
    }
  }
  throw_if_bad(bad);
  std::vector<Vec3> inv;
  average(inc_start_, inc_, en_inv, inv);
  std::vector<NodeStrain> out(num_nodes());
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double A1 = inv[i].x, A2 = inv[i].y;
    // lambda_k^2 = A2 + 1 +- r; (18) in principal axes: tau_k = e^{-A1} (dW/dA1 + dW/dA2 lambda_k^2).
    const double s = A2 + 1, p = std::exp(A1), r = inv[i].z;
    const EnergyDensity d = energy_density(law_, A1, A2);
    out[i] = {A1, A2, std::sqrt(s + r), std::sqrt(std::max(0.0, s - r)), (d.dW_dA1 + d.dW_dA2 * (s + r)) / p,
              (d.dW_dA1 + d.dW_dA2 * (s - r)) / p};
  }
  return out;
}

std::vector<double> ElasticMembrane::node_area(const std::vector<Vec3>& X) const {
  check_size(X);
  const int E = static_cast<int>(num_elements());
  std::vector<Vec3> en_area(6 * E);  // area share in .x (gather works on Vec3)
#pragma omp parallel for schedule(static)
  for (int e = 0; e < E; ++e) {
    const Nodes x = element_nodes(elements_[e], X);
    double S = 0;
    for (int q = 0; q < tri6::kQuadPoints; ++q)
      S += membrane_k::frame(membrane_k::tangents(x, kQuadShape[q])).J * tri6::kQuad[q].w;
    const auto frac = lumping_fractions(x);
    for (int k = 0; k < 6; ++k) en_area[6 * e + k] = {frac[k] * S, 0, 0};
  }
  std::vector<Vec3> node;
  gather(en_area, node);
  std::vector<double> a(node.size());
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = node[i].x;
  return a;
}

std::vector<Vec3> ElasticMembrane::node_normal(const std::vector<Vec3>& X) const {
  check_size(X);
  Work w;
  element_node_pass(X, false, w);
  return w.node_n;
}

// kappa_m^R = tr(kappa)/2 of the reference shape, kappa from (40) averaged at the nodes.
std::vector<double> ElasticMembrane::reference_mean_curvature() const {
  Work w;
  element_node_pass(reference_, false, w);
  curvature_pass(reference_, w);
  std::vector<double> c(num_nodes());
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = 0.5 * trace(w.node_kappa[i]);
  return c;
}

std::size_t ElasticMembrane::memory_bytes() const {
  const std::size_t N = num_nodes(), E = num_elements();
  const std::size_t persistent = E * sizeof(std::array<int, 6>) + N * sizeof(Vec3) +
                                 (inc_start_.size() + inc_.size()) * sizeof(int) +
                                 (ref_node_.size() + ref_quad_.size() + kappa_ref_.size()) * sizeof(double);
  // Workspace of one compute_force with bending (the largest): per element node tau, n, kappa, div, force;
  // per node tau, n, kappa, m, q.
  const std::size_t work = 6 * E * (2 * sizeof(Mat3) + 3 * sizeof(Vec3)) + N * (3 * sizeof(Mat3) + 2 * sizeof(Vec3));
  return persistent + work;
}

}  // namespace immerse
