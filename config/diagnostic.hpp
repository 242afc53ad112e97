#pragma once
// Problems found in a machine file, each with its place, and the one exception type the
// loader lets escape.

#include <string>
#include <vector>

#include "common/error.hpp"

namespace hybridctl::config {

/// One problem at one place. line and column are 1-based; 0 means "the file as a whole"
/// (e.g. it cannot be read).
struct Diagnostic {
  std::string file;
  int line = 0;
  int column = 0;
  std::string message;

  /// "file:line:column: message", or "file: message" when line is 0.
  std::string str() const;
};

/// Thrown by load_machine / parse_machine when the file has any problem. what() lists
/// every diagnostic, one per line, in file order.
class MachineFileError : public hybridctl::InputError {
 public:
  explicit MachineFileError(std::vector<Diagnostic> diagnostics);
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

}  // namespace hybridctl::config
