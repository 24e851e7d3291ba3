#include "arrays.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include <fmt/format.h>

#include "saloam/core/lie.hpp"

namespace saloam::python {
namespace {

std::string dtype_name(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

py::array as_ndarray(const py::handle& value, const char* what) {
  if (!py::isinstance<py::array>(value)) {
    throw py::type_error(fmt::format("{} must be a numpy array, not {}", what,
                                     py::str(py::type::of(value).attr("__name__")).cast<std::string>()));
  }
  return py::reinterpret_borrow<py::array>(value);
}

/// Element (i, j) of a 2-D array of T, through its strides.
template <class T>
T at(const py::array& a, py::ssize_t i, py::ssize_t j) {
  const auto* base = static_cast<const char*>(a.data());
  T v;
  std::memcpy(&v, base + i * a.strides(0) + j * a.strides(1), sizeof(T));
  return v;
}

template <class T>
T at(const py::array& a, py::ssize_t i) {
  const auto* base = static_cast<const char*>(a.data());
  T v;
  std::memcpy(&v, base + i * a.strides(0), sizeof(T));
  return v;
}

template <class T>
void read_points(const py::array& a, LabelledCloud& cloud) {
  const py::ssize_t n = a.shape(0);
  const bool remission = a.shape(1) == 4;
  cloud.points.resize(static_cast<std::size_t>(n));
  cloud.remission.assign(static_cast<std::size_t>(n), 0.0F);
  for (py::ssize_t i = 0; i < n; ++i) {
    const T x = at<T>(a, i, 0), y = at<T>(a, i, 1), z = at<T>(a, i, 2);
    const T r = remission ? at<T>(a, i, 3) : T(0);
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z) || !std::isfinite(r)) {
      throw py::value_error(fmt::format("points: row {} holds a non-finite value ({}, {}, {}{})", i, x, y, z,
                                        remission ? fmt::format(", {}", r) : std::string()));
    }
    cloud.points[static_cast<std::size_t>(i)] =
        Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    cloud.remission[static_cast<std::size_t>(i)] = static_cast<float>(r);
  }
}

/// A 1-D array of n values of an integer or floating kind, read as double.
template <class Out>
std::vector<Out> read_vector(const py::handle& value, const char* what, py::ssize_t n, bool integer) {
  const py::array a = as_ndarray(value, what);
  const char kind = a.dtype().kind();
  const bool ok = integer ? (kind == 'i' || kind == 'u') : (kind == 'f');
  if (!ok) {
    throw py::type_error(fmt::format("{} must be an array of {}, not {}", what, integer ? "integers" : "floats",
                                     dtype_name(a)));
  }
  if (a.ndim() != 1 || a.shape(0) != n) {
    throw py::value_error(fmt::format("{} must have shape ({},), one value per point, not {}", what, n,
                                      py::str(py::cast(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim())))
                                          .cast<std::string>()));
  }
  // Any integer or float width: numpy casts to the widest type of its kind,
  // a copy of one column (the points themselves are never copied so).
  const py::array wide = integer ? py::array(a.attr("astype")(kind == 'u' ? "uint64" : "int64", "C", "same_kind", true, false))
                                 : py::array(a.attr("astype")("float64", "C", "same_kind", true, false));
  std::vector<Out> out(static_cast<std::size_t>(n));
  for (py::ssize_t i = 0; i < n; ++i) {
    if (kind == 'u') {
      const auto v = at<std::uint64_t>(wide, i);
      out[static_cast<std::size_t>(i)] = static_cast<Out>(v);
      if constexpr (std::is_integral_v<Out>) {
        if (v > static_cast<std::uint64_t>(std::numeric_limits<Out>::max()))
          throw py::value_error(fmt::format("{}: value {} at {} is out of range (0..{})", what, v, i,
                                            static_cast<std::uint64_t>(std::numeric_limits<Out>::max())));
      }
    } else if (kind == 'i') {
      const auto v = at<std::int64_t>(wide, i);
      if constexpr (std::is_integral_v<Out>) {
        if (v < 0 || static_cast<std::uint64_t>(v) > static_cast<std::uint64_t>(std::numeric_limits<Out>::max()))
          throw py::value_error(fmt::format("{}: value {} at {} is out of range (0..{})", what, v, i,
                                            static_cast<std::uint64_t>(std::numeric_limits<Out>::max())));
      }
      out[static_cast<std::size_t>(i)] = static_cast<Out>(v);
    } else {
      const auto v = at<double>(wide, i);
      if (!std::isfinite(v)) throw py::value_error(fmt::format("{}: value {} at {} is not finite", what, v, i));
      out[static_cast<std::size_t>(i)] = static_cast<Out>(v);
    }
  }
  return out;
}

}  // namespace

LabelledCloud cloud_from_arrays(const py::handle& points, const py::handle& labels, const py::handle& times,
                                const py::handle& rings) {
  const py::array a = as_ndarray(points, "points");
  const bool is_f32 = a.dtype().is(py::dtype::of<float>());
  const bool is_f64 = a.dtype().is(py::dtype::of<double>());
  if (!is_f32 && !is_f64) throw py::type_error(fmt::format("points must be float32 or float64, not {}", dtype_name(a)));
  if (a.ndim() != 2 || (a.shape(1) != 3 && a.shape(1) != 4)) {
    throw py::value_error(fmt::format(
        "points must have shape (N, 3) (x, y, z) or (N, 4) (x, y, z, remission), not {}",
        py::str(py::cast(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()))).cast<std::string>()));
  }
  LabelledCloud cloud;
  if (is_f32) {
    read_points<float>(a, cloud);
  } else {
    read_points<double>(a, cloud);
  }
  const py::ssize_t n = a.shape(0);
  if (!labels.is_none()) {
    const std::vector<std::uint32_t> raw = read_vector<std::uint32_t>(labels, "labels", n, true);
    cloud.label.resize(raw.size());
    cloud.instance.resize(raw.size());
    for (std::size_t i = 0; i < raw.size(); ++i) {
      cloud.label[i] = static_cast<std::uint16_t>(raw[i] & 0xFFFFU);
      cloud.instance[i] = static_cast<std::uint16_t>(raw[i] >> 16U);
    }
    cloud.has_labels = true;
  } else {
    cloud.label.assign(static_cast<std::size_t>(n), 0);
    cloud.instance.assign(static_cast<std::size_t>(n), 0);
  }
  if (!times.is_none()) cloud.time = read_vector<float>(times, "times", n, false);
  if (!rings.is_none()) cloud.ring = read_vector<std::uint16_t>(rings, "rings", n, true);
  return cloud;
}

py::tuple cloud_to_arrays(const LabelledCloud& cloud) {
  const auto n = static_cast<py::ssize_t>(cloud.size());
  py::array_t<float> points({n, py::ssize_t{4}});
  auto p = points.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& q = cloud.points[static_cast<std::size_t>(i)];
    p(i, 0) = q.x();
    p(i, 1) = q.y();
    p(i, 2) = q.z();
    p(i, 3) = cloud.remission.size() == cloud.size() ? cloud.remission[static_cast<std::size_t>(i)] : 0.0F;
  }
  py::object labels = py::none(), times = py::none(), rings = py::none();
  if (cloud.has_labels) {
    py::array_t<std::uint32_t> l(n);
    auto m = l.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      m(i) = static_cast<std::uint32_t>(cloud.label[k]) |
             (static_cast<std::uint32_t>(cloud.instance.size() == cloud.size() ? cloud.instance[k] : 0) << 16U);
    }
    labels = std::move(l);
  }
  if (cloud.has_times()) times = py::array_t<float>(n, cloud.time.data());
  if (cloud.has_rings()) rings = py::array_t<std::uint16_t>(n, cloud.ring.data());
  return py::make_tuple(points, labels, times, rings);
}

py::array_t<double> pose_to_array(const Pose& pose) {
  py::array_t<double> out({4, 4});
  auto m = out.mutable_unchecked<2>();
  const Eigen::Matrix4d& t = pose.matrix();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = t(r, c);
  return out;
}

py::array_t<double> poses_to_array(const std::vector<Pose>& poses) {
  py::array_t<double> out({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  auto m = out.mutable_unchecked<3>();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Eigen::Matrix4d& t = poses[i].matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m(static_cast<py::ssize_t>(i), r, c) = t(r, c);
  }
  return out;
}

Pose pose_from_array(const py::handle& value, const char* what) {
  const auto a = py::array_t<double, py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
    throw py::value_error(fmt::format("{} must be a 4x4 matrix", what));
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = a.at(r, c);
  if (!m.allFinite()) throw py::value_error(fmt::format("{} holds a non-finite value", what));
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if ((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
      (m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw py::value_error(fmt::format("{} is not a rigid transform (rotation not orthonormal within 1e-3, or last "
                                      "row not 0 0 0 1)",
                                      what));
  }
  Pose pose = Pose::Identity();
  pose.linear() = r;
  pose.translation() = m.topRightCorner<3, 1>();
  // Re-orthonormalised as the readers do a file's, but a pose the library
  // gave (orthonormal to rounding) is kept bit for bit.
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-9 ? orthonormalized(pose) : pose;
}

std::vector<Pose> poses_from_array(const py::handle& value, const char* what) {
  std::vector<Pose> poses;
  for (const py::handle item : value) poses.push_back(pose_from_array(item, what));
  return poses;
}

}  // namespace saloam::python
