#pragma once
// bvhkit::Error: the one exception type the library throws for bad input (files, user data,
// options); FileNotFoundError, derived from it, for an input file that does not exist. Hot paths
// (traversal, refit) never throw.
#include <stdexcept>
#include <string>

namespace bvhkit {

class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A file named as input does not exist: an Error, and distinct so that a caller (Python's
/// FileNotFoundError) can tell a missing file from a damaged one.
class FileNotFoundError : public Error {
  public:
    using Error::Error;
};

}  // namespace bvhkit
