// SPDX-License-Identifier: MIT
// One way for every `wingman` verb to turn a failure into an error line and an exit code.
#pragma once

#include <wingman/common/config.hpp>

#include <exception>
#include <functional>
#include <ostream>
#include <stdexcept>
#include <string_view>

namespace wingman::tools {

/// Runs a verb's `body` and returns its exit code. A failure becomes one line "<verb>: error: <what>" on `err` and
/// exit code 2 for a bad argument or configuration (std::invalid_argument, common::ConfigError) or 1 for any other
/// std::exception. `verb` is the command as the user typed it, e.g. "wingman dataset synth".
inline int run_verb(std::string_view verb, std::ostream& err, const std::function<int()>& body) {
  try {
    return body();
  } catch (const common::ConfigError& e) {
    err << verb << ": error: " << e.what() << std::endl;
    return 2;
  } catch (const std::invalid_argument& e) {
    err << verb << ": error: " << e.what() << std::endl;
    return 2;
  } catch (const std::exception& e) {
    err << verb << ": error: " << e.what() << std::endl;
    return 1;
  }
}

}  // namespace wingman::tools
