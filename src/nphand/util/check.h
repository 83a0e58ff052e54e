// Checks and errors.
//
// Two kinds of failure, kept apart as in COLMAP and FAISS:
//  - bad input from a user or a file: NPHAND_THROW_CHECK* throw nphand::Error with a
//    message that names the problem plus the file and line that raised it;
//  - a broken internal invariant (a bug): NPHAND_CHECK* print and abort. Never used for
//    anything a user can cause.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace nphand {

// What every user-facing error is. `what()` is one line fit to print.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace internal {
[[noreturn]] void ThrowError(const char* file, int line, const std::string& message);
[[noreturn]] void Abort(const char* file, int line, const char* condition, const std::string& message);

template <typename... Args>
std::string Concat(const Args&... args) {
  std::ostringstream out;
  (out << ... << args);
  return out.str();
}
}  // namespace internal

}  // namespace nphand

// Throws nphand::Error("<message> [file:line]") when `condition` is false.
#define NPHAND_THROW_CHECK(condition, ...)                                               \
  do {                                                                                   \
    if (!(condition)) {                                                                  \
      ::nphand::internal::ThrowError(__FILE__, __LINE__,                                 \
                                     ::nphand::internal::Concat(__VA_ARGS__));           \
    }                                                                                    \
  } while (false)

// Throws unconditionally.
#define NPHAND_THROW(...) \
  ::nphand::internal::ThrowError(__FILE__, __LINE__, ::nphand::internal::Concat(__VA_ARGS__))

// Aborts with a message when an internal invariant is broken.
#define NPHAND_CHECK(condition, ...)                                                      \
  do {                                                                                   \
    if (!(condition)) {                                                                  \
      ::nphand::internal::Abort(__FILE__, __LINE__, #condition,                          \
                                ::nphand::internal::Concat("" __VA_OPT__(, ) __VA_ARGS__)); \
    }                                                                                    \
  } while (false)
