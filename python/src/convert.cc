#include "convert.h"

#include <algorithm>

namespace recruit::py_bind {

void Fail(const std::string& message) { throw py::value_error(message); }

DoubleArray AsArray(const py::object& obj, const std::string& name) {
  DoubleArray a = DoubleArray::ensure(obj);
  if (!a) Fail(name + ": must be an array of numbers");
  return a;
}

Eigen::MatrixXd ToMatrix(const py::object& obj, const std::string& name) {
  DoubleArray a = AsArray(obj, name);
  if (a.ndim() == 0) return Eigen::MatrixXd::Constant(1, 1, *a.data());
  if (a.ndim() != 2) {
    Fail(name + ": must be a 2-D array, got " + std::to_string(a.ndim()) + " dimensions");
  }
  // C order (row-major) -> Eigen's column-major.
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  return Eigen::Map<const RowMajor>(a.data(), a.shape(0), a.shape(1));
}

Eigen::VectorXd ToVector(const py::object& obj, const std::string& name) {
  DoubleArray a = AsArray(obj, name);
  if (a.ndim() == 0) return Eigen::VectorXd::Constant(1, *a.data());
  if (a.ndim() != 1) {
    Fail(name + ": must be a 1-D array, got " + std::to_string(a.ndim()) + " dimensions");
  }
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.shape(0));
}

py::array_t<double> FromMatrix(const Eigen::MatrixXd& M) {
  py::array_t<double> out({M.rows(), M.cols()});
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  Eigen::Map<RowMajor>(out.mutable_data(), M.rows(), M.cols()) = M;
  return out;
}

py::array_t<double> FromVector(const Eigen::VectorXd& x) {
  py::array_t<double> out(x.size());
  std::copy(x.data(), x.data() + x.size(), out.mutable_data());
  return out;
}

std::string TransitionName(estimation::TransitionSource t) {
  switch (t) {
    case estimation::TransitionSource::kBroadcast:
      return "broadcast";
    case estimation::TransitionSource::kExplicit:
      return "explicit";
    case estimation::TransitionSource::kConstant:
      return "constant";
  }
  return "?";
}

}  // namespace recruit::py_bind
