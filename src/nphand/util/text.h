// Text as nphand writes it into JSON: file names are bytes, JSON strings are UTF-8.
#pragma once

#include <string>
#include <string_view>

namespace nphand {

// `text` unchanged when it is valid UTF-8; otherwise each byte that is not part of a valid
// UTF-8 sequence becomes the four characters "\xNN" (upper-case hex), so that a file name
// that is not UTF-8 can still be named in JSON and told apart from others.
std::string Utf8OrEscaped(std::string_view text);

// `text` with its ASCII capitals in lower case (other bytes kept): file extensions and
// keywords compared without regard to case.
std::string AsciiLower(std::string_view text);

}  // namespace nphand
