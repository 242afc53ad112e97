#pragma once
// Errors that cross module boundaries. Bad input from outside the program (a file, a
// YAML document, a G-code line, a network frame, a CLI argument) is an InputError whose
// message names the place and what was expected; the CLI maps it to exit code 3.

#include <stdexcept>
#include <string>

namespace hybridctl {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace hybridctl
