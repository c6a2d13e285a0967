// SPDX-License-Identifier: MIT
// Listing and selecting OpenCL platforms and devices by name substring or index.
#include <algorithm>
#include <cctype>
#include <sstream>
#include <stdexcept>

#include "opencl_runtime.hpp"
#include "wingman/detector/opencl_device.hpp"

namespace wingman::detector {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool is_index(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

std::string trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\0' || std::isspace(static_cast<unsigned char>(s.back())))) s.pop_back();
  return s;
}

std::string type_name(cl_device_type t) {
  if (t & CL_DEVICE_TYPE_GPU) return "GPU";
  if (t & CL_DEVICE_TYPE_CPU) return "CPU";
  if (t & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

/// Index of the entry selected by `wanted` (index or case-insensitive substring; "" = 0), or -1.
int choose(const std::vector<std::string>& names, const std::string& wanted) {
  if (names.empty()) return -1;
  if (wanted.empty()) return 0;
  if (is_index(wanted)) {
    const long i = std::stol(wanted);
    return i < static_cast<long>(names.size()) ? static_cast<int>(i) : -1;
  }
  for (size_t i = 0; i < names.size(); ++i)
    if (lower(names[i]).find(lower(wanted)) != std::string::npos) return static_cast<int>(i);
  return -1;
}

std::vector<cl::Platform> platforms_or_empty() {
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    platforms.clear();  // CL_PLATFORM_NOT_FOUND_KHR: no ICD
  }
  return platforms;
}

std::vector<cl::Device> devices_or_empty(const cl::Platform& platform) {
  std::vector<cl::Device> devices;
  try {
    platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
  } catch (const cl::Error&) {
    devices.clear();
  }
  return devices;
}

std::string available_list() {
  const auto lines = list_opencl_devices();
  if (lines.empty()) return "no OpenCL platform found (is an ICD such as pocl-opencl-icd installed?)";
  // One line: fatal errors are one line on stderr (and one status_t field).
  std::string s = "available:";
  for (size_t i = 0; i < lines.size(); ++i) s += (i == 0 ? " " : "; ") + lines[i];
  return s;
}

}  // namespace

std::vector<std::string> list_opencl_devices() {
  std::vector<std::string> lines;
  const auto platforms = platforms_or_empty();
  for (size_t p = 0; p < platforms.size(); ++p) {
    const auto devices = devices_or_empty(platforms[p]);
    const std::string pname = trimmed(platforms[p].getInfo<CL_PLATFORM_NAME>());
    if (devices.empty()) lines.push_back("platform " + std::to_string(p) + " '" + pname + "' (no devices)");
    for (size_t d = 0; d < devices.size(); ++d) {
      std::ostringstream s;
      s << "platform " << p << " '" << pname << "' / device " << d << " '"
        << trimmed(devices[d].getInfo<CL_DEVICE_NAME>()) << "' (" << type_name(devices[d].getInfo<CL_DEVICE_TYPE>())
        << ", " << trimmed(devices[d].getInfo<CL_DEVICE_VERSION>()) << ", "
        << devices[d].getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>() << " compute units)";
      lines.push_back(s.str());
    }
  }
  return lines;
}

cl::Device select_opencl_device(const OpenClOptions& options) {
  const auto platforms = platforms_or_empty();
  std::vector<std::string> pnames;
  for (const auto& p : platforms) pnames.push_back(trimmed(p.getInfo<CL_PLATFORM_NAME>()));
  if (platforms.empty()) {
    throw std::runtime_error(
        "no OpenCL platform found (no ICD loaded: is pocl-opencl-icd or a GPU's OpenCL driver installed, and "
        "OCL_ICD_VENDORS / OCL_ICD_FILENAMES, if set, right?)");
  }
  const int p = choose(pnames, options.platform);
  if (p < 0)
    throw std::runtime_error("opencl.platform = '" + options.platform + "' matches no OpenCL platform; " +
                             available_list());
  const auto devices = devices_or_empty(platforms[p]);
  std::vector<std::string> dnames;
  for (const auto& d : devices) dnames.push_back(trimmed(d.getInfo<CL_DEVICE_NAME>()));
  const int d = choose(dnames, options.device);
  if (d < 0)
    throw std::runtime_error("opencl.device = '" + options.device + "' matches no device of platform '" + pnames[p] +
                             "'; " + available_list());
  return devices[d];
}

std::string describe_cl_error(const cl::Error& e, const std::string& what) {
  return what + ": " + e.what() + " failed with OpenCL error " + std::to_string(e.err());
}

}  // namespace wingman::detector
