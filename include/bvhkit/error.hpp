#pragma once
// bvhkit::Error: the one exception type the library throws for bad input (files, user data,
// options). Hot paths (traversal, refit) never throw.
#include <stdexcept>
#include <string>

namespace bvhkit {

class Error : public std::runtime_error {
  public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace bvhkit
