#pragma once
// numpy arrays to and from the library's types: scans (LabelledCloud),
// poses (4x4), pose lists (N x 4 x 4). Inputs are read through their strides
// (a view of a larger array is read as it is, never made contiguous first),
// checked for shape, dtype and finite values (TypeError for a wrong type,
// ValueError for a wrong shape or value), and copied once into the
// library's own frame type, whose fields are separate arrays of float32
// points, remission, labels, rings and times.

#include <optional>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "saloam/core/types.hpp"

namespace saloam::python {

namespace py = pybind11;

/// A scan from numpy arrays: points (N, 3) or (N, 4) (x, y, z[, remission]),
/// float32 or float64; labels (N,) integers (SemanticKITTI .label values:
/// class in the low 16 bits, instance in the high 16) or None; times (N,)
/// per-point times [s] relative to the scan's stamp, or None; rings (N,)
/// beam indices or None.
LabelledCloud cloud_from_arrays(const py::handle& points, const py::handle& labels, const py::handle& times,
                                const py::handle& rings);

/// The arrays of a scan: points (N, 4) float32, labels (N,) uint32 or None,
/// times (N,) float32 or None, rings (N,) uint16 or None.
py::tuple cloud_to_arrays(const LabelledCloud& cloud);

py::array_t<double> pose_to_array(const Pose& pose);
py::array_t<double> poses_to_array(const std::vector<Pose>& poses);
/// A 4x4 array (or anything numpy makes one of) as a pose; ValueError otherwise.
Pose pose_from_array(const py::handle& value, const char* what);
/// (N, 4, 4) or a sequence of 4x4 arrays as poses.
std::vector<Pose> poses_from_array(const py::handle& value, const char* what);

}  // namespace saloam::python
