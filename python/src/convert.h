// NumPy <-> Eigen conversions and C++ errors -> Python exceptions, shared by the binding files.
// Every Result error becomes a ValueError carrying the C++ message (the CLI's text).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Dense>
#include <string>
#include <utility>

#include "common/result.h"
#include "estimation/filter_model.h"

namespace recruit::py_bind {

namespace py = pybind11;

[[noreturn]] void Fail(const std::string& message);

template <class T>
T Take(Result<T>&& r) {
  if (!r.ok()) Fail(r.error());
  return std::move(r).value();
}

inline void Check(const Status& s) {
  if (!s.ok()) Fail(s.error());
}

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Any array-like of numbers as a C-contiguous double array; `name` labels the error.
DoubleArray AsArray(const py::object& obj, const std::string& name);
// A 2-D array (a scalar reads as 1 x 1).
Eigen::MatrixXd ToMatrix(const py::object& obj, const std::string& name);
// A 1-D array (a scalar reads as one entry).
Eigen::VectorXd ToVector(const py::object& obj, const std::string& name);
py::array_t<double> FromMatrix(const Eigen::MatrixXd& M);
py::array_t<double> FromVector(const Eigen::VectorXd& x);

// "broadcast", "explicit", "constant".
std::string TransitionName(estimation::TransitionSource t);

}  // namespace recruit::py_bind
