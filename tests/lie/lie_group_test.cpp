// Properties shared by SO(3) and SE(3): identities and every analytic Jacobian against numerical
// differentiation, on random inputs and on edge-case angles (0, tiny, series threshold, near pi).
#include <gtest/gtest.h>

#include "../support/lie_test_support.hpp"

namespace taiga::lie {
namespace {

using test::numericalJacobian;
using test::RandomLie;

template <class G>
struct GroupTraits;

template <>
struct GroupTraits<SO3> {
  using Tangent = Vector3;
  using Jacobian = Matrix3;
  static Tangent tangentWithAngle(RandomLie& r, double angle) { return r.unitVector() * angle; }
  static SO3 random(RandomLie& r) { return r.so3(); }
};

template <>
struct GroupTraits<SE3> {
  using Tangent = Vector6;
  using Jacobian = Matrix6;
  static Tangent tangentWithAngle(RandomLie& r, double angle) {
    return makeTangent(r.translation(), r.unitVector() * angle);
  }
  static SE3 random(RandomLie& r) { return r.se3(); }
};

template <class G>
class LieGroupTest : public ::testing::Test {
 protected:
  using Traits = GroupTraits<G>;

  // Tangents at every edge-case angle plus random ones, all with angle below pi.
  std::vector<typename Traits::Tangent> tangents() {
    std::vector<typename Traits::Tangent> out;
    for (double angle : test::edgeCaseAngles())
      out.push_back(Traits::tangentWithAngle(rng_, angle));
    for (int i = 0; i < 30; ++i) out.push_back(Traits::tangentWithAngle(rng_, 3.1 * i / 30.0));
    return out;
  }
  std::vector<G> elements() {
    std::vector<G> out;
    for (const auto& tau : tangents()) out.push_back(G::Exp(tau));
    return out;
  }
  G random() { return Traits::random(rng_); }

  RandomLie rng_{42};
};

using Groups = ::testing::Types<SO3, SE3>;
TYPED_TEST_SUITE(LieGroupTest, Groups);

// Numerical differentiation with step 1e-6 is accurate to about 1e-9 on these inputs.
constexpr double kJacobianTol = 1e-6;

TYPED_TEST(LieGroupTest, ExpLogRoundTrip) {
  for (const auto& tau : this->tangents()) {
    EXPECT_TRUE(TypeParam::Exp(tau).Log().isApprox(tau, 1e-9) || tau.norm() < 1e-9)
        << tau.transpose();
    EXPECT_LT((TypeParam::Exp(tau).Log() - tau).norm(), 1e-9 * (1.0 + tau.norm()));
  }
  for (int i = 0; i < 50; ++i) {
    const TypeParam X = this->random();
    EXPECT_TRUE(TypeParam::Exp(X.Log()).matrix().isApprox(X.matrix(), 1e-12));
  }
}

TYPED_TEST(LieGroupTest, JacobianInversesAndLeftRightRelation) {
  using Jacobian = typename TestFixture::Traits::Jacobian;
  for (const auto& tau : this->tangents()) {
    const Jacobian I = Jacobian::Identity();
    EXPECT_TRUE(
        (TypeParam::rightJacobian(tau) * TypeParam::rightJacobianInverse(tau)).isApprox(I, 1e-9));
    EXPECT_TRUE(
        (TypeParam::leftJacobian(tau) * TypeParam::leftJacobianInverse(tau)).isApprox(I, 1e-9));
    // Jl(tau) = Adj(Exp(tau)) Jr(tau)
    EXPECT_TRUE(TypeParam::leftJacobian(tau).isApprox(
        TypeParam::Exp(tau).adjoint() * TypeParam::rightJacobian(tau), 1e-9));
  }
}

TYPED_TEST(LieGroupTest, RightAndLeftJacobiansMatchNumerical) {
  using Tangent = typename TestFixture::Traits::Tangent;
  for (const auto& tau : this->tangents()) {
    // Jr = d Exp(tau + d) (-) Exp(tau) / dd (right), Jl the same with the left minus.
    const auto Jr = numericalJacobian([](const Tangent& t) { return TypeParam::Exp(t); }, tau);
    EXPECT_TRUE(TypeParam::rightJacobian(tau).isApprox(Jr, kJacobianTol)) << tau.transpose();
    typename TestFixture::Traits::Jacobian Jl;
    for (int i = 0; i < Tangent::RowsAtCompileTime; ++i) {
      const Tangent d = Tangent::Unit(i) * 1e-6;
      Jl.col(i) = (TypeParam::Exp(tau + d).minusLeft(TypeParam::Exp(tau)) -
                   TypeParam::Exp(tau - d).minusLeft(TypeParam::Exp(tau))) /
                  2e-6;
    }
    EXPECT_TRUE(TypeParam::leftJacobian(tau).isApprox(Jl, kJacobianTol)) << tau.transpose();
  }
}

TYPED_TEST(LieGroupTest, ExpAndLogJacobiansMatchNumerical) {
  using Tangent = typename TestFixture::Traits::Tangent;
  using Jacobian = typename TestFixture::Traits::Jacobian;
  for (const auto& tau : this->tangents()) {
    Jacobian J_exp, J_log;
    const TypeParam X = TypeParam::Exp(tau, &J_exp);
    X.Log(&J_log);
    EXPECT_TRUE(J_exp.isApprox(
        numericalJacobian([](const Tangent& t) { return TypeParam::Exp(t); }, tau), kJacobianTol));
    EXPECT_TRUE(J_log.isApprox(numericalJacobian([](const TypeParam& Y) { return Y.Log(); }, X),
                               kJacobianTol))
        << tau.transpose();
  }
}

TYPED_TEST(LieGroupTest, InverseAndComposeJacobiansMatchNumerical) {
  using Jacobian = typename TestFixture::Traits::Jacobian;
  for (int i = 0; i < 30; ++i) {
    const TypeParam X = this->random(), Y = this->random();
    Jacobian J_inv, J_X, J_Y;
    const TypeParam X_inv = X.inverse(&J_inv);
    EXPECT_TRUE((X * X_inv).matrix().isApprox(TypeParam().matrix(), 1e-12));
    EXPECT_TRUE(J_inv.isApprox(numericalJacobian([](const TypeParam& A) { return A.inverse(); }, X),
                               kJacobianTol));
    X.compose(Y, &J_X, &J_Y);
    EXPECT_TRUE(J_X.isApprox(numericalJacobian([&](const TypeParam& A) { return A * Y; }, X),
                             kJacobianTol));
    EXPECT_TRUE(J_Y.isApprox(numericalJacobian([&](const TypeParam& B) { return X * B; }, Y),
                             kJacobianTol));
  }
}

TYPED_TEST(LieGroupTest, PlusMinusJacobiansMatchNumerical) {
  using Tangent = typename TestFixture::Traits::Tangent;
  using Jacobian = typename TestFixture::Traits::Jacobian;
  for (const auto& tau : this->tangents()) {
    const TypeParam X = this->random();
    Jacobian J_X, J_tau;
    const TypeParam Y = X.plus(tau, &J_X, &J_tau);
    EXPECT_TRUE(J_X.isApprox(numericalJacobian([&](const TypeParam& A) { return A.plus(tau); }, X),
                             kJacobianTol));
    EXPECT_TRUE(J_tau.isApprox(numericalJacobian([&](const Tangent& t) { return X.plus(t); }, tau),
                               kJacobianTol));

    Jacobian J_d_Y, J_d_X;
    const Tangent d = Y.minus(X, &J_d_Y, &J_d_X);
    EXPECT_LT((d - tau).norm(), 1e-9 * (1.0 + tau.norm()));
    EXPECT_TRUE(J_d_Y.isApprox(numericalJacobian([&](const TypeParam& B) { return B.minus(X); }, Y),
                               kJacobianTol))
        << tau.transpose();
    EXPECT_TRUE(J_d_X.isApprox(numericalJacobian([&](const TypeParam& A) { return Y.minus(A); }, X),
                               kJacobianTol))
        << tau.transpose();
  }
}

TYPED_TEST(LieGroupTest, AdjointProperty) {
  // X Exp(tau) X^-1 = Exp(Adj(X) tau), and Adj is a homomorphism: Adj(XY) = Adj(X) Adj(Y).
  for (const auto& tau : this->tangents()) {
    const TypeParam X = this->random(), Y = this->random();
    EXPECT_TRUE((X * TypeParam::Exp(tau) * X.inverse())
                    .matrix()
                    .isApprox(TypeParam::Exp(X.adjoint() * tau).matrix(), 1e-9));
    EXPECT_TRUE((X * Y).adjoint().isApprox(X.adjoint() * Y.adjoint(), 1e-12));
  }
}

TYPED_TEST(LieGroupTest, LeftAndRightPlusMinusAreConsistent) {
  for (const auto& tau : this->tangents()) {
    const TypeParam X = this->random();
    // tau (+) X = X (+) Adj(X)^-1 tau
    const typename TestFixture::Traits::Tangent local = X.adjoint().inverse() * tau;
    EXPECT_TRUE(X.plusLeft(tau).matrix().isApprox(X.plus(local).matrix(), 1e-9));
    EXPECT_LT((X.plusLeft(tau).minusLeft(X) - tau).norm(), 1e-9 * (1.0 + tau.norm()));
  }
}

TYPED_TEST(LieGroupTest, InterpolationFollowsTheGeodesic) {
  for (int i = 0; i < 30; ++i) {
    const TypeParam X0 = this->random(), X1 = this->random();
    EXPECT_TRUE(interpolate(X0, X1, 0.0).matrix().isApprox(X0.matrix(), 1e-12));
    EXPECT_TRUE(interpolate(X0, X1, 1.0).matrix().isApprox(X1.matrix(), 1e-9));
    // Constant speed: the step from s=0.25 to s=0.75 is half of the whole step, expressed at
    // the same point, and the midpoint splits the path in two equal halves.
    const auto whole = X1.minus(X0);
    const TypeParam quarter = interpolate(X0, X1, 0.25), three_quarters = interpolate(X0, X1, 0.75);
    EXPECT_LT((three_quarters.minus(quarter) - 0.5 * whole).norm(), 1e-9);
    const TypeParam mid = interpolate(X0, X1, 0.5);
    EXPECT_LT((mid.minus(X0) - X1.minus(mid)).norm(), 1e-9);
  }
}

}  // namespace
}  // namespace taiga::lie
