// SPDX-License-Identifier: MIT
// Internal: the OpenCL C++ bindings as the detector uses them (OpenCL 1.2), device selection, kernel sources.
#pragma once

#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#define CL_HPP_ENABLE_EXCEPTIONS
#include <CL/opencl.hpp>

#include <map>
#include <string>

#include "wingman/detector/opencl_options.hpp"

namespace wingman::detector {

namespace opencl_sources {
/// Every detector/kernels/*.cl file by name ("conv2d_blocked.cl"), embedded at build time.
const std::map<std::string, std::string>& all();
}  // namespace opencl_sources

/// The device chosen by options.platform / options.device. Throws std::runtime_error listing every
/// platform and device when nothing matches.
cl::Device select_opencl_device(const OpenClOptions& options);

/// "what: clFunction failed with CL_ERROR_NAME (-n)" for a cl::Error.
std::string describe_cl_error(const cl::Error& e, const std::string& what);

}  // namespace wingman::detector
