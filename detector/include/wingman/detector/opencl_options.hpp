// SPDX-License-Identifier: MIT
// Options of the OpenCL inference backend (the `opencl.*` keys of config/detector.yaml).
#pragma once

#include <string>
#include <vector>

namespace wingman::detector {

/// Which OpenCL device runs the CNN and how. Defaults run on the first device of the first platform.
struct OpenClOptions {
  std::string platform;  ///< platform: name substring (case-insensitive) or index; "" = first platform
  std::string device;    ///< device of that platform: name substring (case-insensitive) or index; "" = first
  int max_batch = 4;     ///< most images per forward() (zoom-in crops run as one batch); buffers sized for it
  std::string build_options = "-cl-mad-enable";  ///< extra options passed to clBuildProgram

  template <class V>
  void visit(V& v) {
    v("opencl.platform", platform, "OpenCL platform: name substring or index; empty = first");
    v("opencl.device", device, "OpenCL device of that platform: name substring or index; empty = first");
    v("opencl.max_batch", max_batch, "most images per forward pass (zoom-in crops run as one batch), 1..64");
    v("opencl.build_options", build_options, "extra OpenCL compiler options");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
};

}  // namespace wingman::detector
