#include "CliSupport.h"

#include <fmt/core.h>

#include <cstdio>

namespace fct::cli {

int reportError(const std::string& message) {
  std::string oneLine = message;
  for (char& c : oneLine) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  fmt::print(stderr, "error: {}\n", oneLine);
  return kExitError;
}

}  // namespace fct::cli
