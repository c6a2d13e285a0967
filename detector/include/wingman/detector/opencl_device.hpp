// SPDX-License-Identifier: MIT
// OpenCL platforms and devices of this machine, for device selection, error messages and `wingman bench`.
#pragma once

#include <string>
#include <vector>

namespace wingman::detector {

/// One line per device: "platform P 'name' / device D 'name' (type, OpenCL version, compute units)".
/// Empty when there is no OpenCL platform (no ICD installed); never throws.
std::vector<std::string> list_opencl_devices();

}  // namespace wingman::detector
