// SPDX-License-Identifier: MIT
// The one place of the copies between the fixed-size arrays of Wingman's LCM messages (own_pose_t, setpoint_t,
// target_t, vehicle_truth_t) and Eigen: vectors, quaternions, 3x3 matrices. Values are copied as they are (no frame
// change, no normalization): ned_enu.hpp converts frames.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace wingman::geometry {

/// A vector from a message's double[3] (x, y, z), e.g. own_pose_t.p_body_in_world, target_t.v_target_in_world.
inline Eigen::Vector3d to_vector3(const double (&a)[3]) { return {a[0], a[1], a[2]}; }

/// A quaternion from a message's double[4] in the order (w, x, y, z) of every Wingman message
/// (own_pose_t.q_body_to_world, vehicle_truth_t.q_body_to_world). Not normalized: the caller decides.
inline Eigen::Quaterniond to_quaternion(const double (&q)[4]) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]); }

/// A 3x3 matrix from a message's row-major double[9] (target_t.position_covariance, velocity_covariance).
inline Eigen::Matrix3d to_matrix3(const double (&a)[9]) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(a);
}

/// The symmetric 3x3 matrix of a message's upper triangle row by row, (xx, xy, xz, yy, yz, zz)
/// (own_pose_t.cov_p_body_in_world).
inline Eigen::Matrix3d from_upper_triangle(const double (&a)[6]) {
  Eigen::Matrix3d m;
  m << a[0], a[1], a[2],  //
      a[1], a[3], a[4],   //
      a[2], a[4], a[5];
  return m;
}

/// A vector into a message's double[3] (x, y, z).
inline void to_array(const Eigen::Vector3d& v, double (&out)[3]) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

/// A quaternion into a message's double[4] in the order (w, x, y, z), as it is (not normalized).
inline void to_array(const Eigen::Quaterniond& q, double (&out)[4]) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

/// A 3x3 matrix into a message's row-major double[9].
inline void to_array(const Eigen::Matrix3d& m, double (&out)[9]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[3 * r + c] = m(r, c);
}

/// The upper triangle of a symmetric 3x3 matrix into a message's double[6], row by row: (xx, xy, xz, yy, yz, zz).
/// The lower triangle is not read.
inline void to_upper_triangle(const Eigen::Matrix3d& m, double (&out)[6]) {
  out[0] = m(0, 0);
  out[1] = m(0, 1);
  out[2] = m(0, 2);
  out[3] = m(1, 1);
  out[4] = m(1, 2);
  out[5] = m(2, 2);
}

}  // namespace wingman::geometry
