// Strain-energy laws (22)-(24), alone and with the area dilation energy W_D = (K_D/2)(ln J)^2: derivatives
// against central differences, isotropic tension against the closed forms, small-strain moduli, bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "immerse/membrane/MaterialLaw.hpp"

using namespace immerse;

namespace {

const MaterialLaw kLaws[] = {NeoHookean{2.5},
                             Yeoh{0.7, 0.04},
                             Skalak{0.3, 4.0},
                             WithAreaDilation<NeoHookean>{NeoHookean{2.5}, 40.0},
                             WithAreaDilation<Yeoh>{Yeoh{0.7, 0.04}, 40.0},
                             WithAreaDilation<Skalak>{Skalak{0.3, 4.0}, 40.0}};

/// Closed forms derived in the law headers for equal principal stretches lambda; the area dilation energy adds
/// tau_D = K_D ln J / J with J = lambda^2.
double closed_form_tension(const MaterialLaw& law, double l) {
  const auto dilated = [&](const auto* w) {
    const double J = l * l;
    return closed_form_tension(w->law, l) + w->K_D * std::log(J) / J;
  };
  if (const auto* w = std::get_if<WithAreaDilation<NeoHookean>>(&law)) return dilated(w);
  if (const auto* w = std::get_if<WithAreaDilation<Yeoh>>(&law)) return dilated(w);
  if (const auto* w = std::get_if<WithAreaDilation<Skalak>>(&law)) return dilated(w);
  if (const auto* w = std::get_if<NeoHookean>(&law)) return w->Es / 3 * (1 - std::pow(l, -6));
  if (const auto* w = std::get_if<Yeoh>(&law)) {
    const double I = 2 * l * l + std::pow(l, -4) - 3;
    return 2 * (w->C10 + 3 * w->C30 * I * I) * (1 - std::pow(l, -6));
  }
  const auto& w = std::get<Skalak>(law);
  return w.C11 / 2 * (l * l - 1) + w.C21 / 2 * l * l * (std::pow(l, 4) - 1);
}

}  // namespace

TEST(MembraneMaterial, DerivativesMatchCentralDifferences) {
  const double h = 1e-5;
  for (const auto& law : kLaws)
    for (double A1 : {-0.3, 0.0, 0.2, 0.7})
      for (double A2 : {-0.2, 0.05, 0.4, 1.3}) {
        const EnergyDensity d = energy_density(law, A1, A2);
        const double fd1 = (energy_density(law, A1 + h, A2).W - energy_density(law, A1 - h, A2).W) / (2 * h);
        const double fd2 = (energy_density(law, A1, A2 + h).W - energy_density(law, A1, A2 - h).W) / (2 * h);
        const double scale = 1 + std::fabs(d.dW_dA1) + std::fabs(d.dW_dA2);
        EXPECT_LT(std::fabs(d.dW_dA1 - fd1) / scale, 1e-9) << law.index() << " " << A1 << " " << A2;
        EXPECT_LT(std::fabs(d.dW_dA2 - fd2) / scale, 1e-9) << law.index() << " " << A1 << " " << A2;
      }
}

TEST(MembraneMaterial, IsotropicTensionMatchesClosedForm) {
  for (const auto& law : kLaws)
    for (double l : {0.8, 1.0, 1.05, 1.3, 7.0 / 5}) {
      const double tau = isotropic_tension(law, l), exact = closed_form_tension(law, l);
      EXPECT_NEAR(tau, exact, 1e-13 * (1 + std::fabs(exact))) << law.index() << " lambda " << l;
    }
}

TEST(MembraneMaterial, RestStateIsStressFreeAndEnergyFree) {
  for (const auto& law : kLaws) {
    EXPECT_NEAR(energy_density(law, 0, 0).W, 0, 1e-15);
    EXPECT_NEAR(isotropic_tension(law, 1.0), 0, 1e-15);
  }
}

// Small-strain area modulus K = dtau/d(area strain) at lambda = 1, area strain = lambda^2 - 1:
// neo-Hookean Ks = Es (notes), Yeoh with C10 = mu0/2, C30 = mu0/30: 3 mu0, Skalak: C11/2 + C21 = Gs (1 + 2C).
TEST(MembraneMaterial, SmallStrainAreaModuli) {
  const double h = 1e-6;
  auto K = [&](const MaterialLaw& law) {
    return (isotropic_tension(law, std::sqrt(1 + h)) - isotropic_tension(law, std::sqrt(1 - h))) / (2 * h);
  };
  EXPECT_NEAR(K(NeoHookean{3.0}), 3.0, 1e-8);
  const double mu0 = 0.8;
  EXPECT_NEAR(K(Yeoh{mu0 / 2, mu0 / 30}), 3 * mu0, 1e-8);
  EXPECT_NEAR(K(Skalak{0.2, 5.0}), 0.1 + 5.0, 1e-8);
  // The area dilation energy adds K_D.
  EXPECT_NEAR(K(with_area_dilation(Skalak{0.2, 5.0}, 70.0)), 0.1 + 5.0 + 70.0, 1e-7);
  EXPECT_NEAR(K(with_area_dilation(NeoHookean{3.0}, 70.0)), 3.0 + 70.0, 1e-7);
  EXPECT_NEAR(K(without_area_dilation(with_area_dilation(NeoHookean{3.0}, 70.0))), 3.0, 1e-8);
}

// Skalak's compressive tension peaks at J = 1/sqrt(3) and softens below (a compressed patch past it collapses at
// a bounded energy); with the area dilation energy the tension keeps falling as J -> 0.
TEST(MembraneMaterial, AreaDilationEnergyHasNoCompressiveSoftening) {
  const Skalak skalak{0.2, 2.0};
  const MaterialLaw plain = skalak, dilated = with_area_dilation(skalak, 20.0);
  const double peak = std::pow(1.0 / 3, 0.25);  // lambda at J = 1/sqrt(3)
  EXPECT_GT(isotropic_tension(plain, 0.5 * peak), isotropic_tension(plain, peak));  // softened
  double last = 0;
  for (double J = 0.99; J > 1e-3; J *= 0.9) {
    const double tau = isotropic_tension(dilated, std::sqrt(J));
    EXPECT_LT(tau, last) << "J = " << J;
    last = tau;
  }
  EXPECT_LT(last, -1e5);  // K_D ln J / J = -1.2e5 at J = 1.1e-3
}

// The neo-Hookean Laplace pressure of an inflated sphere, dp a / Gs = 2 tau / (lambda Gs), peaks at
// lambda = 7^(1/6) with the value 1.239463 (docs/theory/conventions.md).
TEST(MembraneMaterial, NeoHookeanLaplacePeak) {
  const double Es = 3.0, Gs = Es / 3;
  const double l = std::pow(7.0, 1.0 / 6);
  auto dp = [&](double s) { return 2 * isotropic_tension(NeoHookean{Es}, s) / (s * Gs); };
  EXPECT_NEAR(dp(l), 1.239463, 1e-6);
  EXPECT_LT(dp(l * 1.01), dp(l));
  EXPECT_LT(dp(l / 1.01), dp(l));
}

TEST(MembraneMaterial, NonPositiveModulusIsAnInputError) {
  try {
    NeoHookean{0.0};
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "membrane.law.Es = 0: must be > 0");
  }
  EXPECT_THROW(NeoHookean{-1.0}, InputError);
  EXPECT_THROW((Yeoh{0.0, 0.1}), InputError);
  EXPECT_THROW((Yeoh{1.0, -0.1}), InputError);
  EXPECT_THROW((Skalak{-2.0, 1.0}), InputError);
  EXPECT_THROW((Skalak{1.0, -1.0}), InputError);
  try {
    Skalak{1.0, -3.0};
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "membrane.law.C21 = -3: must be >= 0");
  }
  EXPECT_THROW((WithAreaDilation<Skalak>{Skalak{1.0, 1.0}, -1.0}), InputError);
}
