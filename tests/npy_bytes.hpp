#pragma once
// The bytes of a .npy file (format 1.0) built by hand, for tests and benchmarks that craft
// their own inputs. Free of GoogleTest so that the benchmarks can include it too.

#include <string>

namespace evcorner::test {

/// A .npy file (format 1.0): the header dict `dict_body` padded so that the data starts
/// on a 64-byte boundary, then `data`.
inline std::string npy_file(const std::string& dict_body, const std::string& data) {
    std::string dict = dict_body;
    while ((10 + dict.size() + 1) % 64 != 0) dict += ' ';
    dict += '\n';
    std::string f("\x93NUMPY\x01\x00", 8);
    f += static_cast<char>(dict.size() & 0xFF);
    f += static_cast<char>(dict.size() >> 8);
    return f + dict + data;
}

}  // namespace evcorner::test
