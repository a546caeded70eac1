// Verification studies of the fluid–membrane coupling, paper §2.2 (eqs. 6–8, 14):
//   delta_moments          — the discrete moment conditions of the kernels φ (eq. 8 and Peskin 4-point)
//   ib_adjointness         — spreading and interpolation are adjoint: ⟨S F, u⟩ h³ = ⟨F, J u⟩
//   ib_interpolation_order — interpolation error O(h²); spreading conserves force and torque
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/verify/Convergence.hpp"
#include "immerse/verify/Study.hpp"

namespace immerse::verify {

namespace {

const DeltaKernel kKernels[] = {RomaPeskin3{}, Peskin4{}};

// --- delta_moments ---------------------------------------------------------------------------

std::vector<Check> delta_moments(bool quick) {
  std::vector<Check> checks;
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> shift(-3.0, 3.0);
  const int shifts = quick ? 2000 : 200000;

  // Point values quoted in docs/theory/conventions.md, "Discrete delta functions".
  const RomaPeskin3 r3;
  const Peskin4 p4;
  const double point_error =
      std::fmax(std::fmax(std::abs(r3.phi(0) - 2.0 / 3), std::abs(r3.phi(0.5) - 0.5)),
                std::fmax(std::fmax(std::abs(r3.phi(1) - 1.0 / 6), std::abs(r3.phi(1.5))),
                          std::fmax(std::fmax(std::abs(p4.phi(0) - 0.5), std::abs(p4.phi(1) - 0.25)),
                                    std::abs(p4.phi(2)))));
  checks.push_back({"phi(0), phi(1/2), phi(1), phi(support) of roma3 and peskin4", point_error, "<=", 1e-15});

  for (const auto& kernel : kKernels) {
    const std::string name = kernel_name(kernel);
    const double square_sum = name == "roma3" ? 0.5 : 0.375;
    double e0 = 0, e1 = 0, e2 = 0, e_even_odd = 0, e_weights = 0;
    for (int n = 0; n < shifts; ++n) {
      const double s = n < 3 ? 0.5 * n : shift(rng);  // s = 0, 1/2, 1 exactly, then random
      double m0 = 0, m1 = 0, m2 = 0, even = 0;
      const int j0 = static_cast<int>(std::floor(s)) - 3;
      for (int j = j0; j <= j0 + 7; ++j) {
        const double p = phi(kernel, s - j);
        m0 += p;
        m1 += (s - j) * p;
        m2 += p * p;
        if (j % 2 == 0) even += p;
      }
      e0 = std::fmax(e0, std::abs(m0 - 1));
      e1 = std::fmax(e1, std::abs(m1));
      e2 = std::fmax(e2, std::abs(m2 - square_sum));
      e_even_odd = std::fmax(e_even_odd, std::fmax(std::abs(even - 0.5), std::abs(m0 - even - 0.5)));
      // The grouped weights the coupler uses equal φ at the same points.
      std::visit(
          [&](const auto& k) {
            double w[std::decay_t<decltype(k)>::width];
            const int i0 = k.weights(s, w);
            for (int m = 0; m < k.width; ++m) e_weights = std::fmax(e_weights, std::abs(w[m] - k.phi(s - (i0 + m))));
          },
          kernel);
    }
    checks.push_back({name + ": max |sum phi - 1|", e0, "<=", 1e-14});
    checks.push_back({name + ": max |sum (s-j) phi|", e1, "<=", 1e-14});
    checks.push_back({name + ": max |sum phi^2 - " + (name == "roma3" ? "1/2" : "3/8") + "|", e2, "<=", 1e-14});
    if (name == "peskin4") checks.push_back({name + ": max |even sum - 1/2|, |odd sum - 1/2|", e_even_odd, "<=", 1e-14});
    checks.push_back({name + ": max |grouped weights - phi|", e_weights, "<=", 1e-14});
  }
  return checks;
}

// --- ib_adjointness --------------------------------------------------------------------------

/// Random nodes in the domain, with extra nodes on and near every wall (down to distance 0) and
/// around the periodic seam (including coordinates several periods away).
std::vector<Vec3> test_nodes(const Grid& g, int count, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Vec3> X(count);
  for (int l = 0; l < count; ++l) {
    for (int a = 0; a < 3; ++a) {
      const double lo = g.origin()[a], L = g.length(a), h = g.h();
      const double u = unit(rng);
      const int kind = l % 4;  // 0: anywhere, 1: near the low end, 2: near the high end, 3: exactly on it
      double x = lo + u * L;
      if (kind == 1) x = lo + 2.5 * h * u;
      if (kind == 2) x = lo + L - 2.5 * h * u;
      if (kind == 3) x = (l / 4) % 2 ? lo : lo + L;
      if (g.periodic(a) && l % 7 == 0) x += (l % 3 - 1) * 3 * L + (u - 0.5) * 1e-3 * h;  // far away and across the seam
      X[l][a] = x;
    }
  }
  return X;
}

std::vector<Check> ib_adjointness(bool quick) {
  std::vector<Check> checks;
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> normal;
  const int nodes = quick ? 400 : 4000;
  for (int combo = 0; combo < 8; ++combo) {
    std::array<Boundary, 3> bc;
    std::string tag;
    for (int a = 0; a < 3; ++a) {
      bc[a] = (combo >> a) & 1 ? Boundary::Wall : Boundary::Periodic;
      tag += bc[a] == Boundary::Wall ? 'W' : 'P';
    }
    const Grid g({10, 12, 8}, {0.5, 0.6, 0.4}, bc, {-0.3, 0.2, -0.1});
    const auto X = test_nodes(g, nodes, rng);
    std::vector<Vec3> F(nodes), U(nodes);
    for (auto& f : F) f = {normal(rng), normal(rng), normal(rng)};
    FaceField u(g), f(g);
    for (int d = 0; d < 3; ++d)
      for (auto& v : u[d].values()) v = normal(rng);
    for (const auto& kernel : kKernels) {
      IBCoupler coupler(g, kernel);
      coupler.spread_force(X, F, f);
      coupler.interpolate_velocity(u, X, U);
      double grid_side = 0, node_side = 0, scale = 0;
      for (int d = 0; d < 3; ++d)
        for (std::size_t p = 0; p < u[d].size(); ++p) grid_side += f[d][p] * u[d][p];
      grid_side *= g.cell_volume();
      for (int l = 0; l < nodes; ++l)
        for (int d = 0; d < 3; ++d) {
          node_side += F[l][d] * U[l][d];
          scale += std::abs(F[l][d] * U[l][d]);
        }
      checks.push_back({kernel_name(kernel) + " " + tag + ": |<SF,u> h^3 - <F,Ju>| / sum|F Ju|",
                        std::abs(grid_side - node_side) / scale, "<=", 1e-13});
    }
  }
  return checks;
}

// --- ib_interpolation_order ------------------------------------------------------------------

/// A smooth velocity field, periodic on the unit cube.
Vec3 smooth_velocity(const Vec3& x) {
  constexpr double k = 2 * M_PI;
  return {std::sin(k * x.x + 1) * std::cos(k * x.y) * std::sin(k * x.z + 0.5),
          std::cos(k * x.x) * std::sin(k * x.y + 0.3) + 0.2 * std::cos(k * x.z),
          std::sin(k * (x.x + x.y)) * std::cos(k * x.z - 0.7)};
}

FaceField sample(const Grid& g, Vec3 (*field)(const Vec3&)) {
  FaceField u(g);
  for (int d = 0; d < 3; ++d) {
    const auto s = g.face_shape(d);
    for (int k = 0; k < s[2]; ++k)
      for (int j = 0; j < s[1]; ++j)
        for (int i = 0; i < s[0]; ++i) u[d](i, j, k) = field(g.face_position(d, i, j, k))[d];
  }
  return u;
}

std::vector<Check> ib_interpolation_order(bool quick) {
  std::vector<Check> checks;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> interior(0.25, 0.75);  // >= 2 h from the walls on the coarsest grid
  const int count = quick ? 200 : 2000;
  std::vector<Vec3> X(count), U(count);
  for (auto& x : X) x = {interior(rng), interior(rng), interior(rng)};
  const std::vector<int> sizes = quick ? std::vector<int>{16, 32, 64} : std::vector<int>{16, 32, 64, 128};

  for (const auto bcs : {Boundary::Periodic, Boundary::Wall}) {
    std::vector<double> errors[2];  // per kernel, coarsest grid first
    for (const int n : sizes) {
      const Grid g({n, n, n}, {1, 1, 1}, {bcs, bcs, bcs});
      const FaceField u = sample(g, smooth_velocity);
      for (int kk = 0; kk < 2; ++kk) {
        IBCoupler(g, kKernels[kk]).interpolate_velocity(u, X, U);
        double e = 0;
        for (int l = 0; l < count; ++l) e = std::fmax(e, norm(U[l] - smooth_velocity(X[l])));
        errors[kk].push_back(e);
      }
    }
    for (int kk = 0; kk < 2; ++kk) {
      const std::string tag = kernel_name(kKernels[kk]) + (bcs == Boundary::Wall ? ", walls" : ", periodic");
      checks.push_back({tag + ": order of max interpolation error", min_observed_order(errors[kk]), ">=", 1.9});
      checks.push_back({tag + ": max interpolation error, h = 1/" + std::to_string(sizes.back()), errors[kk].back(),
                        "<=", 1e-2});
    }
  }

  // Spreading a unit force: Σ f h³ = F and Σ x × f h³ = X × F (first moment of φ), for nodes
  // anywhere in a periodic box and nodes away from the walls of a closed one.
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Vec3 F = normalized(Vec3{0.3, -0.7, 0.65});
  for (const auto bcs : {Boundary::Periodic, Boundary::Wall}) {
    const Grid g({16, 16, 16}, {1, 1, 1}, {bcs, bcs, bcs}, {-0.5, -0.25, 0.1});
    for (const auto& kernel : kKernels) {
      IBCoupler coupler(g, kernel);
      FaceField f(g);
      double force_error = 0, torque_error = 0;
      for (int trial = 0; trial < (quick ? 20 : 200); ++trial) {
        // Away from the periodic seam too, so that the face positions do not jump by L.
        Vec3 x;
        for (int a = 0; a < 3; ++a) x[a] = g.origin()[a] + 0.2 + 0.6 * unit(rng);
        const Vec3 Xs[1] = {x}, Fs[1] = {F};
        coupler.spread_force(Xs, Fs, f);
        Vec3 total, torque;
        for (int d = 0; d < 3; ++d) {
          const auto s = g.face_shape(d);
          for (int k = 0; k < s[2]; ++k)
            for (int j = 0; j < s[1]; ++j)
              for (int i = 0; i < s[0]; ++i) {
                Vec3 fd;
                fd[d] = f[d](i, j, k) * g.cell_volume();
                total += fd;
                torque += cross(g.face_position(d, i, j, k), fd);
              }
        }
        force_error = std::fmax(force_error, norm(total - F));
        torque_error = std::fmax(torque_error, norm(torque - cross(x, F)) / norm(x));
      }
      const std::string tag = kernel_name(kernel) + (bcs == Boundary::Wall ? ", walls" : ", periodic");
      checks.push_back({tag + ": |sum f h^3 - F| / |F|", force_error, "<=", 1e-14});
      checks.push_back({tag + ": |sum x x f h^3 - X x F| / (|X| |F|)", torque_error, "<=", 1e-14});
    }
  }
  return checks;
}

}  // namespace

std::vector<Study> coupling_studies() {
  return {
      {"delta_moments", "discrete delta kernels roma3 (eq. 8) and peskin4: point values and moment conditions",
       delta_moments},
      {"ib_adjointness",
       "spreading (eq. 6) and interpolation (eq. 14) are adjoint, <SF,u>h^3 = <F,Ju>, for all 8 periodic/wall "
       "combinations",
       ib_adjointness},
      {"ib_interpolation_order",
       "interpolation (eq. 14) of a smooth field converges as h^2; spreading (eq. 6) conserves force and torque",
       ib_interpolation_order},
  };
}

}  // namespace immerse::verify
