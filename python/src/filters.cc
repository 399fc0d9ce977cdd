#include "filters.h"

#include <vector>

#include "convert.h"
#include "estimation/population_chain.h"

namespace recruit::py_bind {

// ---------------------------------------------------------------------------------------------
// The base: checks, missing samples, the offline run.

void PyFilter::Predict(const py::object& A) {
  const Eigen::MatrixXd M = ToMatrix(A, "A");
  Check(estimation::ValidateColumnStochastic(M, estimation::kStochasticTolerance,
                                             model_.num_states(), "A"));
  DoPredict(M);
}

void PyFilter::PredictBroadcast(double p_on, double p_off) {
  if (model_.transition != estimation::TransitionSource::kBroadcast) {
    Fail("predict_broadcast: the filter model's transition is '" +
         TransitionName(model_.transition) + "', not 'broadcast' (use predict(A))");
  }
  Check(estimation::BroadcastTransitionModel::ValidateInputs(p_on, p_off, "predict_broadcast"));
  DoPredictBroadcast(p_on, p_off);
}

bool PyFilter::Update(const py::object& y) {
  if (y.is_none()) return false;
  const Eigen::VectorXd v = ToVector(y, "y");
  if (v.size() > 0 && v.array().isNaN().all()) return false;
  if (v.array().isNaN().any()) {
    Fail("y: some entries are NaN and some are not; a missing sample is all-NaN (or None)");
  }
  if (v.size() != model_.num_outputs()) {
    Fail("measurement: must have " + std::to_string(model_.num_outputs()) + " entries, got " +
         std::to_string(v.size()));
  }
  if (!v.allFinite()) Fail("measurement: entries must be finite");
  DoUpdate(v);
  return true;
}

py::tuple PyFilter::Run(const py::object& ys, const py::object& p_on, const py::object& p_off,
                        const py::object& As) {
  const Eigen::MatrixXd Y = ToMatrix(ys, "ys");
  const Eigen::Index T = Y.rows();
  const int m = model_.num_states();
  if (Y.cols() != model_.num_outputs()) {
    Fail("ys: must be T x " + std::to_string(model_.num_outputs()) +
         " (one column per output), got " + std::to_string(Y.rows()) + " x " +
         std::to_string(Y.cols()));
  }
  Eigen::VectorXd pon, poff;
  std::vector<Eigen::MatrixXd> Ak;
  const bool broadcast = !p_on.is_none() || !p_off.is_none();
  if (broadcast && !As.is_none()) Fail("run: pass either p_on and p_off or A, not both");
  if (broadcast) {
    if (model_.transition != estimation::TransitionSource::kBroadcast) {
      Fail("run: p_on/p_off need a broadcast filter model");
    }
    if (p_on.is_none() || p_off.is_none()) Fail("run: pass both p_on and p_off");
    pon = ToVector(p_on, "p_on");
    poff = ToVector(p_off, "p_off");
    if (pon.size() < T - 1 || poff.size() < T - 1) {
      Fail("run: p_on and p_off need at least T - 1 = " + std::to_string(T - 1) + " entries");
    }
    for (Eigen::Index k = 0; k + 1 < T; ++k) {
      Check(estimation::BroadcastTransitionModel::ValidateInputs(pon(k), poff(k),
                                                                 "run: step " + std::to_string(k)));
    }
  } else if (!As.is_none()) {
    DoubleArray a = AsArray(As, "A");
    if (a.ndim() == 2) {
      Ak.push_back(ToMatrix(As, "A"));
    } else if (a.ndim() == 3 && a.shape(0) >= T - 1) {
      using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
      const py::ssize_t stride = a.shape(1) * a.shape(2);
      for (py::ssize_t k = 0; k < a.shape(0); ++k) {
        Ak.emplace_back(Eigen::Map<const RowMajor>(a.data() + k * stride, a.shape(1), a.shape(2)));
      }
    } else {
      Fail("run: A must be m x m (constant) or (T - 1) x m x m");
    }
    for (size_t k = 0; k < Ak.size(); ++k) {
      Check(estimation::ValidateColumnStochastic(Ak[k], estimation::kStochasticTolerance, m,
                                                 "run: A[" + std::to_string(k) + "]"));
    }
  } else if (model_.transition == estimation::TransitionSource::kConstant) {
    Ak.push_back(model_.A);
  } else if (T > 1) {
    Fail("run: this model's transition is '" + TransitionName(model_.transition) +
         "': pass p_on and p_off or A");
  }
  for (Eigen::Index k = 0; k < T; ++k) {
    const auto row = Y.row(k).array();
    if (row.isNaN().any() && !row.isNaN().all()) {
      Fail("ys: row " + std::to_string(k) + " is partly NaN; a missing sample is all-NaN");
    }
    if (!row.isNaN().all() && !row.allFinite()) {
      Fail("ys: row " + std::to_string(k) + " has an infinite entry");
    }
  }
  Eigen::MatrixXd X(T, m), V(T, m);
  {
    py::gil_scoped_release release;
    Eigen::VectorXd mean(m), var(m), y(Y.cols());
    for (Eigen::Index k = 0; k < T; ++k) {
      if (k > 0) {
        if (broadcast) {
          DoPredictBroadcast(pon(k - 1), poff(k - 1));
        } else {
          DoPredict(Ak.size() == 1 ? Ak[0] : Ak[k - 1]);
        }
      }
      if (!Y.row(k).array().isNaN().all()) {
        y = Y.row(k).transpose();
        DoUpdate(y);
      }
      MeanAndVariance(mean, var);
      X.row(k) = mean.transpose();
      V.row(k) = var.transpose();
    }
  }
  return py::make_tuple(FromMatrix(X), FromMatrix(V));
}

// ---------------------------------------------------------------------------------------------
// The Kalman filter, fixed or dynamic size.

namespace {

template <int M, int R>
class KalmanCoreT final : public KalmanCore {
 public:
  using F = estimation::PopulationKalmanFilterT<M, R>;
  explicit KalmanCoreT(F f) : f_(std::move(f)) {}
  void Predict(const Eigen::MatrixXd& A) override {
    if constexpr (M == Eigen::Dynamic) {
      f_.Predict(A);
    } else {
      f_.Predict(typename F::Mat(A));  // a stack copy
    }
  }
  void PredictBroadcast(double p_on, double p_off) override { f_.PredictBroadcast(p_on, p_off); }
  void Update(const Eigen::VectorXd& y) override {
    y_ = y;  // fixed size: a copy, no allocation
    f_.Update(y_);
  }
  void SetOutput(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R_) override {
    f_.SetOutput(typename F::OutputMat(H), typename F::OutMat(R_));
  }
  Eigen::VectorXd estimate() const override { return f_.estimate(); }
  Eigen::MatrixXd covariance() const override { return f_.covariance(); }
  Eigen::VectorXd innovation() const override { return f_.innovation(); }
  Eigen::MatrixXd gain() const override { return f_.gain(); }
  Eigen::MatrixXd H() const override { return f_.H(); }
  void MeanAndVariance(Eigen::VectorXd& mean, Eigen::VectorXd& var) const override {
    mean = f_.estimate();
    var = f_.covariance().diagonal();
  }
  bool fixed_size() const override { return M != Eigen::Dynamic; }

 private:
  F f_;
  typename F::OutVec y_;
};

template <int M, int R>
std::unique_ptr<KalmanCore> MakeCoreT(const estimation::FilterModel& model,
                                      estimation::CovarianceMode mode, const Eigen::VectorXd& x0,
                                      const Eigen::MatrixXd& P0) {
  return std::make_unique<KalmanCoreT<M, R>>(
      Take(estimation::PopulationKalmanFilterT<M, R>::Create(model, mode, x0, P0)));
}

// The same sizes as MakeCountFilter (src/estimation/count_filter.cc), so that a fixed-size
// filter here is the one `recruit filter` runs.
std::unique_ptr<KalmanCore> MakeCore(const estimation::FilterModel& model,
                                     estimation::CovarianceMode mode, const Eigen::VectorXd& x0,
                                     const Eigen::MatrixXd& P0, bool fixed) {
  if (fixed && model.num_outputs() == 1) {
    switch (model.num_states()) {
      case 2:
        return MakeCoreT<2, 1>(model, mode, x0, P0);
      case 3:
        return MakeCoreT<3, 1>(model, mode, x0, P0);
      case 20:
        return MakeCoreT<20, 1>(model, mode, x0, P0);
    }
  }
  return MakeCoreT<Eigen::Dynamic, Eigen::Dynamic>(model, mode, x0, P0);
}

}  // namespace

PyKalmanFilter::PyKalmanFilter(const estimation::FilterModel& model, const std::string& mode,
                               const py::object& x0, const py::object& P0, bool fixed_size)
    : PyFilter(model), mode_(Take(estimation::ParseCovarianceMode(mode))), want_fixed_(fixed_size) {
  Reset(x0, P0);
}

void PyKalmanFilter::Reset(const py::object& x0, const py::object& P0) {
  // Re-created, so that the belief is validated (sizes, sum N, PSD); the mode is kept.
  core_ = MakeCore(model_, mode_, x0.is_none() ? model_.x0 : ToVector(x0, "x0"),
                   P0.is_none() ? model_.P0 : ToMatrix(P0, "P0"), want_fixed_);
}

void PyKalmanFilter::SetOutput(const py::object& H, const py::object& R) {
  const Eigen::MatrixXd h = ToMatrix(H, "H"), r = ToMatrix(R, "R");
  const Eigen::Index m = model_.num_states(), nr = model_.num_outputs();
  if (h.rows() != nr || h.cols() != m) {
    Fail("set_output: H must be " + std::to_string(nr) + " x " + std::to_string(m));
  }
  if (r.rows() != nr || r.cols() != nr) {
    Fail("set_output: R must be " + std::to_string(nr) + " x " + std::to_string(nr));
  }
  if (!h.allFinite() || !r.allFinite()) Fail("set_output: H and R must be finite");
  if ((r - r.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1 + r.cwiseAbs().maxCoeff()) ||
      r.llt().info() != Eigen::Success) {
    Fail("set_output: R must be symmetric positive definite");
  }
  core_->SetOutput(h, r);
  model_.H = h;  // the run and the properties see the new output model
  model_.R = r;
}

void PyKalmanFilter::DoPredictBroadcast(double p_on, double p_off) {
  core_->PredictBroadcast(p_on, p_off);
}

// ---------------------------------------------------------------------------------------------
// The baselines.

namespace {

estimation::ExactBayesFilter MakeExact(const estimation::FilterModel& model, uint64_t max_states,
                                       uint64_t cache_bytes) {
  estimation::ExactFilterOptions o;
  o.max_states = max_states;
  o.cache_bytes = cache_bytes;
  return Take(estimation::ExactBayesFilter::Create(model, o));
}

estimation::ParticleFilter MakeParticle(const estimation::FilterModel& model, int particles,
                                        double threshold, Rng& rng) {
  if (particles < 1) Fail("particles: must be >= 1, got " + std::to_string(particles));
  if (!(threshold >= 0.0 && threshold <= 1.0)) {
    Fail("resample_threshold: must be in [0, 1], got " + std::to_string(threshold));
  }
  estimation::ParticleFilterOptions o;
  o.num_particles = particles;
  o.resample_threshold = threshold;
  return Take(estimation::ParticleFilter::Create(model, o, rng));
}

}  // namespace

PyExactFilter::PyExactFilter(const estimation::FilterModel& model, uint64_t max_states,
                             uint64_t cache_bytes)
    : PyFilter(model), f_(MakeExact(model, max_states, cache_bytes)) {}

PyParticleFilter::PyParticleFilter(const estimation::FilterModel& model, int particles,
                                   double resample_threshold, uint64_t seed)
    : PyFilter(model), rng_(seed), f_(MakeParticle(model, particles, resample_threshold, rng_)) {}

}  // namespace recruit::py_bind
