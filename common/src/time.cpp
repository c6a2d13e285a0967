// SPDX-License-Identifier: MIT
// Clock helpers.
#include "wingman/common/time.hpp"

#include <ctime>

namespace wingman::common {
namespace {
int64_t clock_utime(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}
}  // namespace

int64_t wall_utime() { return clock_utime(CLOCK_REALTIME); }
int64_t monotonic_utime() { return clock_utime(CLOCK_MONOTONIC); }

}  // namespace wingman::common
