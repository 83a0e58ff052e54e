#include "nphand/util/check.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace nphand::internal {

void ThrowError(const char* file, int line, const std::string& message) {
  throw Error(message + " [" + std::filesystem::path(file).filename().string() + ":" +
              std::to_string(line) + "]");
}

void Abort(const char* file, int line, const char* condition, const std::string& message) {
  std::fprintf(stderr, "nphand: internal error at %s:%d: check failed: %s %s\n", file, line,
               condition, message.c_str());
  std::abort();
}

}  // namespace nphand::internal
