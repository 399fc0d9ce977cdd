// The population Kalman filter against the paper's equations worked by hand and against a
// textbook Kalman filter written out with explicit inverses.
#include <gtest/gtest.h>

#include "estimation/population_kalman_filter.h"
#include "test_util.h"

namespace recruit {
namespace file_kalman_filter_test {

// m = 2, r = 1: X^ = (6, 4), P = 2 [1 -1; -1 1], N = 10,
// A = [0.9 0.3; 0.1 0.7], H = [0 1], R = 0.5, y = 4.
estimation::FilterModel HandModel() {
  estimation::FilterModel f = estimation::FilterModel::TwoState(10, 1.0, 1.0, std::sqrt(0.5));
  f.transition = estimation::TransitionSource::kExplicit;
  return f;
}

struct HandCase {
  estimation::CovarianceMode mode;
  double qz;  // the scalar c with Qz = c [1 -1; -1 1]
};

class EstimationKalmanHandStep : public ::testing::TestWithParam<HandCase> {};

TEST_P(EstimationKalmanHandStep, MatchesEquationsWorkedByHand) {
  const HandCase c = GetParam();
  Eigen::Matrix2d A;
  A << 0.9, 0.3, 0.1, 0.7;
  Eigen::Matrix2d P0;
  P0 << 2, -2, -2, 2;
  auto f =
      estimation::PopulationKalmanFilter::Create(HandModel(), c.mode, Eigen::Vector2d(6, 4), P0);
  ASSERT_TRUE(f.ok()) << f.error();
  f->Predict(A);
  // (16): A X^ = (0.9*6 + 0.3*4, 0.1*6 + 0.7*4) = (6.6, 3.4).
  EXPECT_NEAR(f->estimate()(0), 6.6, 1e-12);
  EXPECT_NEAR(f->estimate()(1), 3.4, 1e-12);
  // A P A^T: A (1, -1) = (0.6, -0.6), so A P A^T = 2 * 0.36 [1 -1; -1 1] = 0.72 [..].
  const double p_pred = 0.72 + c.qz;
  EXPECT_NEAR(f->covariance()(0, 0), p_pred, 1e-12);
  EXPECT_NEAR(f->covariance()(0, 1), -p_pred, 1e-12);
  EXPECT_NEAR(f->covariance()(1, 1), p_pred, 1e-12);
  f->Update(Eigen::VectorXd::Constant(1, 4.0));
  // (17) y^ = 3.4; S = H P H^T + R = p_pred + 0.5; K = (-p_pred, p_pred) / S (19).
  const double S = p_pred + 0.5;
  const double k = p_pred / S;
  EXPECT_NEAR(f->innovation()(0), 0.6, 1e-12);
  EXPECT_NEAR(f->gain()(0, 0), -k, 1e-12);
  EXPECT_NEAR(f->gain()(1, 0), k, 1e-12);
  EXPECT_NEAR(f->estimate()(0), 6.6 - k * 0.6, 1e-12);  // (15)
  EXPECT_NEAR(f->estimate()(1), 3.4 + k * 0.6, 1e-12);
  // (20): P = (1 - k) p_pred [1 -1; -1 1] = p_pred * 0.5 / S.
  const double p_post = p_pred * 0.5 / S;
  EXPECT_NEAR(f->covariance()(0, 0), p_post, 1e-12);
  EXPECT_NEAR(f->covariance()(0, 1), -p_post, 1e-12);
  EXPECT_NEAR(f->covariance()(1, 1), p_post, 1e-12);
}

// Qz (eq. 25) for m = 2 is sum_j x_j a_1j (1 - a_1j) [1 -1; -1 1]:
//   extended at X^ = (6, 4):      6 * 0.9 * 0.1 + 4 * 0.3 * 0.7 = 0.54 + 0.84 = 1.38
//   conservative at X = (10, 10): 10 * 0.09 + 10 * 0.21 = 3.0
//   plain:                        0
INSTANTIATE_TEST_SUITE_P(Modes, EstimationKalmanHandStep,
                         ::testing::Values(HandCase{estimation::CovarianceMode::kExtended, 1.38},
                                           HandCase{estimation::CovarianceMode::kConservative, 3.0},
                                           HandCase{estimation::CovarianceMode::kPlain, 0.0}),
                         [](const auto& info) { return std::string(ToString(info.param.mode)); });

// The fixed-size path gives the same numbers as the dynamic one.
TEST(EstimationKalman, FixedSizeMatchesDynamic) {
  Eigen::Matrix2d A;
  A << 0.9, 0.3, 0.1, 0.7;
  Eigen::Matrix2d P0;
  P0 << 2, -2, -2, 2;
  auto d = estimation::PopulationKalmanFilter::Create(
      HandModel(), estimation::CovarianceMode::kExtended, Eigen::Vector2d(6, 4), P0);
  auto s = estimation::PopulationKalmanFilterT<2, 1>::Create(
      HandModel(), estimation::CovarianceMode::kExtended, Eigen::Vector2d(6, 4), P0);
  ASSERT_TRUE(d.ok() && s.ok());
  for (int t = 0; t < 50; ++t) {
    d->Predict(A);
    s->Predict(A);
    if (t % 3 != 0) {
      d->Update(Eigen::VectorXd::Constant(1, 3.0 + 0.1 * t));
      s->Update(Eigen::Matrix<double, 1, 1>(3.0 + 0.1 * t));
    }
  }
  EXPECT_LT((d->estimate() - s->estimate()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((d->covariance() - s->covariance()).cwiseAbs().maxCoeff(), 1e-12);
}

// m = 3, r = 2, with process noise: one step against a textbook Kalman filter written with an
// explicit inverse and the factored Joseph form.
TEST(EstimationKalman, MatchesTextbookFilterWithTwoOutputsAndProcessNoise) {
  estimation::FilterModel f;
  f.state_names = {"a", "b", "c"};
  f.N = 30;
  f.H.resize(2, 3);
  f.H << 1.0, 0.5, 0.0, 0.0, 0.2, 1.0;
  f.R.resize(2, 2);
  f.R << 0.4, 0.1, 0.1, 0.3;
  f.G.resize(3, 1);
  f.G << 1.0, -1.0, 0.0;  // moves agents a <-> b: column sums of G Qw G^T are zero
  f.Qw = Eigen::MatrixXd::Constant(1, 1, 0.7);
  f.transition = estimation::TransitionSource::kExplicit;
  f.x0 = Eigen::Vector3d(10, 15, 5);
  f.P0 = Eigen::MatrixXd::Zero(3, 3);
  Eigen::Matrix3d A;
  A << 0.8, 0.1, 0.2, 0.15, 0.7, 0.3, 0.05, 0.2, 0.5;
  Eigen::Matrix3d P0;
  P0 << 2, -1, -1, -1, 1.5, -0.5, -1, -0.5, 1.5;
  const Eigen::Vector3d x0(10, 15, 5);
  const Eigen::Vector2d y(17.0, 9.0);
  auto kf =
      estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended, x0, P0);
  ASSERT_TRUE(kf.ok()) << kf.error();
  kf->Predict(A);
  kf->Update(y);

  // Reference.
  Eigen::Matrix3d Qz = Eigen::Matrix3d::Zero();
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d a = A.col(j);
    Qz += x0(j) * (Eigen::Matrix3d(a.asDiagonal()) - a * a.transpose());
  }
  const Eigen::Matrix3d Pp = A * P0 * A.transpose() + f.G * f.Qw * f.G.transpose() + Qz;
  const Eigen::Vector3d xp = A * x0;
  const Eigen::Matrix<double, 3, 2> K =
      Pp * f.H.transpose() * (f.H * Pp * f.H.transpose() + f.R).inverse();
  const Eigen::Vector3d xu = xp + K * (y - f.H * xp);
  const Eigen::Matrix3d IKH = Eigen::Matrix3d::Identity() - K * f.H;
  const Eigen::Matrix3d Pu = IKH * Pp * IKH.transpose() + K * f.R * K.transpose();
  EXPECT_LT((kf->estimate() - xu).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((kf->covariance() - Pu).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(kf->estimate().sum(), 30.0, 1e-12);
}

// An estimate with a negative count (possible after an update): the extended mode evaluates Qz
// at the projection onto {n >= 0, sum = N}, so the predicted P is A P A^T + Qz(proj X^) with a
// PSD Qz. Reference: the free functions ProjectOntoSimplex and ProcessCovarianceQz.
TEST(EstimationKalman, ExtendedModeProjectsNegativeEstimates) {
  estimation::FilterModel f;
  f.state_names = {"a", "b", "c"};
  f.N = 10;
  f.H = Eigen::RowVector3d(1.0, 0.0, 0.0);
  f.R = Eigen::MatrixXd::Constant(1, 1, 0.01);
  f.G = Eigen::MatrixXd::Zero(3, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = estimation::TransitionSource::kExplicit;
  f.x0 = Eigen::Vector3d(2, 4, 4);
  f.P0 = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d P0;
  P0 << 8, -4, -4, -4, 8, -4, -4, -4, 8;
  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended,
                                                       f.x0, P0);
  ASSERT_TRUE(kf.ok());
  kf->Update(Eigen::VectorXd::Constant(1, 12.0));  // above N: pushes b and c below 0
  const Eigen::VectorXd x = kf->estimate();
  const Eigen::MatrixXd P = kf->covariance();
  ASSERT_LT(x.minCoeff(), 0.0) << x.transpose();
  Eigen::Matrix3d A;
  A << 0.5, 0.2, 0.1, 0.3, 0.6, 0.2, 0.2, 0.2, 0.7;
  kf->Predict(A);
  const Eigen::VectorXd xp = estimation::ProjectOntoSimplex(x, 10.0);
  const Eigen::MatrixXd Qz = estimation::ProcessCovarianceQz(A, xp);
  EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Qz).eigenvalues().minCoeff(), -1e-12);
  const Eigen::MatrixXd expected = A * P * A.transpose() + Qz;
  EXPECT_LT((kf->covariance() - expected).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((kf->estimate() - A * x).cwiseAbs().maxCoeff(), 1e-12);
  // The projection mattered: Qz at the raw estimate is a different matrix.
  EXPECT_GT((estimation::ProcessCovarianceQz(A, x) - Qz).cwiseAbs().maxCoeff(), 0.1);
}

TEST(EstimationKalman, RejectsBadInitialBeliefAndInputs) {
  const estimation::FilterModel f = HandModel();
  auto bad_sum = estimation::PopulationKalmanFilter::Create(
      f, estimation::CovarianceMode::kExtended, Eigen::Vector2d(6, 5), Eigen::Matrix2d::Zero());
  ASSERT_FALSE(bad_sum.ok());
  EXPECT_NE(bad_sum.error().find("sum to N = 10"), std::string::npos) << bad_sum.error();
  auto bad_size = estimation::PopulationKalmanFilter::Create(
      f, estimation::CovarianceMode::kExtended, Eigen::Vector3d(6, 4, 0), Eigen::Matrix2d::Zero());
  EXPECT_FALSE(bad_size.ok());
  auto fixed_wrong =
      estimation::PopulationKalmanFilterT<3, 1>::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_FALSE(fixed_wrong.ok());
  EXPECT_NE(fixed_wrong.error().find("m = 3"), std::string::npos);

  auto kf = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(kf.ok());
  Eigen::Matrix2d A;
  A << 0.9, 0.3, 0.2, 0.7;  // column 0 sums to 1.1
  Status s = kf->PredictChecked(A);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().find("column 0 sums to 1.1"), std::string::npos) << s.error();
  EXPECT_FALSE(kf->UpdateChecked(Eigen::VectorXd::Constant(1, NAN)).ok());
  EXPECT_FALSE(kf->UpdateChecked(Eigen::VectorXd::Zero(2)).ok());
  EXPECT_EQ(kf->estimate(), Eigen::Vector2d(10, 0));  // untouched by the rejected inputs
}

// R growing with the units in transit, R(x^-) = R + n R_transit + n^2 R_transit2 with
// n = TransitCount(x^-), against a textbook filter written out densely (explicit Qz, Joseph form
// with its own R_k) over a run of broadcasts and measurements of the three-state unit, whose
// only state in transit is "warming" (interior 0.4 on the diagonal; weight (0.45 - 0.2) / 0.45,
// its force step to "on" over the force range). The dynamic and the fixed-size filters both.
TEST(EstimationKalman, TransitNoiseMatchesTextbookFilterWithStateDependentR) {
  estimation::FilterModel f = testing_util::ThreeStateModel(40, 0.3);
  f.R_transit = Eigen::MatrixXd::Constant(1, 1, 0.05);
  f.R_transit2 = Eigen::MatrixXd::Constant(1, 1, 0.004);
  const double w = (0.45 - 0.2) / 0.45;
  EXPECT_LT((f.TransitWeights() - Eigen::Vector3d(0, w, 0)).cwiseAbs().maxCoeff(), 1e-15);
  auto d = estimation::PopulationKalmanFilter::Create(f, estimation::CovarianceMode::kExtended);
  auto s =
      estimation::PopulationKalmanFilterT<3, 1>::Create(f, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(d.ok() && s.ok());
  Eigen::Vector3d x = f.x0;
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  const Eigen::RowVector3d h = f.H;
  const double r0 = f.R(0, 0), rt = f.R_transit(0, 0), rt2 = f.R_transit2(0, 0);
  for (int t = 0; t < 60; ++t) {
    const double p_on = 0.05 + 0.1 * ((t / 7) % 3), p_off = 0.02 + 0.04 * ((t / 5) % 4);
    d->PredictBroadcast(p_on, p_off);
    s->PredictBroadcast(p_on, p_off);
    const Eigen::Matrix3d A = f.broadcast.Matrix(p_on, p_off);
    ASSERT_TRUE((x.array() >= 0).all()) << t;  // Qz at x itself (the extended mode, feasible)
    Eigen::Matrix3d Qz = Eigen::Matrix3d::Zero();
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d a = A.col(j);
      Qz += x(j) * (Eigen::Matrix3d(a.asDiagonal()) - a * a.transpose());
    }
    P = A * P * A.transpose() + Qz;
    x = A * x;
    if (t % 4 == 3) continue;  // a lost sample: prediction only
    const double y = 0.2 * x(1) + 0.45 * x(2) + 0.7 * std::sin(0.9 * t);
    const double n = w * std::max(0.0, x(1));
    const double R = r0 + rt * n + rt2 * n * n;
    EXPECT_NEAR(d->TransitCount(), n, 1e-9) << t;
    const double S = (h * P * h.transpose())(0, 0) + R;
    const Eigen::Vector3d K = P * h.transpose() / S;
    x += K * (y - h.dot(x));
    const Eigen::Matrix3d IKH = Eigen::Matrix3d::Identity() - K * h;
    P = IKH * P * IKH.transpose() + K * R * K.transpose();
    d->Update(Eigen::VectorXd::Constant(1, y));
    s->Update(Eigen::Matrix<double, 1, 1>(y));
    EXPECT_NEAR(d->innovation_covariance()(0, 0), S, 1e-9 * S) << t;
    EXPECT_NEAR(s->innovation_covariance()(0, 0), S, 1e-9 * S) << t;
  }
  EXPECT_LT((d->estimate() - x).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((d->covariance() - P).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((s->estimate() - x).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((s->covariance() - P).cwiseAbs().maxCoeff(), 1e-9);
}

// A model whose R_transit and R_transit2 are zero is the constant-R filter bit for bit (the path
// of every model file written before they existed); one with either > 0 differs.
TEST(EstimationKalman, ZeroTransitNoiseIsTheConstantFilterBitForBit) {
  const estimation::FilterModel plain = testing_util::ThreeStateModel(40, 0.3);
  estimation::FilterModel zero = plain, some = plain, shared = plain;
  zero.R_transit = Eigen::MatrixXd::Zero(1, 1);
  zero.R_transit2 = Eigen::MatrixXd::Zero(1, 1);
  some.R_transit = Eigen::MatrixXd::Constant(1, 1, 0.05);
  shared.R_transit2 = Eigen::MatrixXd::Constant(1, 1, 0.05);
  auto a = estimation::PopulationKalmanFilter::Create(plain, estimation::CovarianceMode::kExtended);
  auto b = estimation::PopulationKalmanFilter::Create(zero, estimation::CovarianceMode::kExtended);
  auto c = estimation::PopulationKalmanFilter::Create(some, estimation::CovarianceMode::kExtended);
  auto e =
      estimation::PopulationKalmanFilter::Create(shared, estimation::CovarianceMode::kExtended);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok() && e.ok());
  for (int t = 0; t < 60; ++t) {
    for (auto* k : {&*a, &*b, &*c, &*e}) {
      k->PredictBroadcast(0.1, 0.05);
      k->Update(Eigen::VectorXd::Constant(1, 5.0 + std::sin(0.3 * t)));
    }
    ASSERT_EQ(a->estimate(), b->estimate()) << t;
    ASSERT_EQ(a->covariance(), b->covariance()) << t;
  }
  EXPECT_EQ(b->TransitCount(), 0.0);
  EXPECT_GT(c->TransitCount(), 1.0);
  EXPECT_GT((a->estimate() - c->estimate()).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_GT(e->TransitCount(), 1.0);
  EXPECT_GT((a->estimate() - e->estimate()).cwiseAbs().maxCoeff(), 1e-6);
}

}  // namespace file_kalman_filter_test
}  // namespace recruit
