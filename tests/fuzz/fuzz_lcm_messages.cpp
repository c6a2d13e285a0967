// SPDX-License-Identifier: MIT
// Fuzz target: every message type a process subscribes to, through the path of Runtime's subscriptions
// (wire-format check, decode, validate_message). Also checks the wire-format check against LCM's decoder: a
// payload the check accepts must decode, and re-encode to no more bytes than it came in.
#include "fuzz_support.hpp"

#include <cstdlib>
#include <vector>

namespace {

using namespace wingman;

template <class Msg>
void one(const uint8_t* data, size_t size, const common::MessageLimits& limits) {
  if (!common::check_encoded<Msg>(data, size, limits).empty()) return;
  Msg msg;
  const int decoded = msg.decode(data, 0, static_cast<int>(size));  // must not throw: the check passed
  if (decoded < 0 || msg.getEncodedSize() != decoded) {
    std::fprintf(stderr, "check_encoded accepted a %s that LCM decodes to %d (encoded size %d)\n", Msg::getTypeName(),
                 decoded, decoded < 0 ? -1 : msg.getEncodedSize());
    std::abort();
  }
  (void)common::validate_message(msg);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  common::MessageLimits limits;
  limits.image = {640, 480};  // small limits, so the limit checks are reached too
  const uint8_t* p = data + 1;
  const size_t n = size - 1;
  switch (data[0] % 7) {
    case 0:
      one<image_t>(p, n, limits);
      break;
    case 1:
      one<detections_t>(p, n, limits);
      break;
    case 2:
      one<own_pose_t>(p, n, limits);
      break;
    case 3:
      one<targets_t>(p, n, limits);
      break;
    case 4:
      one<setpoint_t>(p, n, limits);
      break;
    case 5:
      one<status_t>(p, n, limits);
      break;
    default:
      one<ground_truth_t>(p, n, limits);
      break;
  }
  return 0;
}
