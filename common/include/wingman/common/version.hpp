// SPDX-License-Identifier: MIT
// The version every executable reports (--version): the project's version and the commit it was built from.
#pragma once

namespace wingman::common {

/// "0.1.0 (git 958641d)": CMake's project version and `git describe --always --tags` of the source tree at build time
/// ("git unknown" when built outside a git checkout). Refreshed on every build (cmake/version_gen.cmake).
const char* version();

}  // namespace wingman::common
