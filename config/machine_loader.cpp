// Loading a machine file: reading it (bounded in size), parsing its one YAML document,
// and handing the document to MachineReader (machine_reader.hpp), which checks the schema.

#include "config/machine_loader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <optional>
#include <cerrno>
#include <sstream>
#include <system_error>
#include <vector>

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include "config/machine_reader.hpp"

namespace hybridctl::config {

namespace {

using namespace detail;

/// Larger files are rejected before parsing; a real machine file is a few kB.
constexpr std::size_t kMaxMachineFileBytes = 16u << 20;

/// Where each document of a stream starts; the parser's events are otherwise ignored.
///
/// yaml-cpp 0.7 reads a document that starts with a token no value can start with (a stray
/// ',', say) as null without consuming that token, so YAML::LoadAll calls the parser again
/// and again on it, allocating without end (jbeder/yaml-cpp#1040, fixed in 0.8). The loader
/// takes at most two parser steps instead: the first document, and whether another follows
/// (one that starts where the first did is that stuck token).
class DocumentStarts final : public YAML::EventHandler {
 public:
  std::vector<YAML::Mark> marks;

  void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}
};

}  // namespace

Machine parse_machine(std::string_view yaml_text, std::string file_name) {
  DiagnosticSink sink(std::move(file_name));
  Machine machine;
  constexpr std::string_view kExpectedDocument =
      "expected a mapping with at least name, envelope, setups and heads or tools (see docs/machine-file.md)";
  try {
    const std::string text(yaml_text);
    std::istringstream stream(text);
    YAML::Parser parser(stream);
    DocumentStarts starts;
    const bool second = parser.HandleNextDocument(starts) && parser.HandleNextDocument(starts);
    const YAML::Node document = YAML::Load(text);  // the first document
    if (second && starts.marks[1].pos == starts.marks[0].pos) {
      const auto at = static_cast<std::size_t>(std::max(starts.marks[0].pos, 0));
      sink.error(starts.marks[0], "YAML syntax error: found '" + printable(yaml_text.substr(at, 1)) +
                                      "', which starts no value; " + std::string(kExpectedDocument));
    } else if (!document || document.IsNull()) {
      sink.error(YAML::Mark::null_mark(), "empty machine file; " + std::string(kExpectedDocument));
    } else {
      if (second)
        sink.error(starts.marks[1], "a machine file holds one YAML document; expected no second document here");
      if (!document.IsMap())
        sink.error(document.Mark(), std::string(kExpectedDocument) + ", got " + describe(document));
      else
        machine = MachineReader(sink).load(document);
    }
  } catch (const YAML::Exception& e) {
    sink.error(e.mark, "YAML syntax error: " + e.msg);
  } catch (const std::exception& e) {
    sink.error(YAML::Mark::null_mark(), std::string("cannot parse: ") + e.what());
  }
  if (!sink.empty()) throw MachineFileError(sink.take_sorted());
  return machine;
}

std::string read_machine_text(const std::filesystem::path& path) {
  const std::string name = path.string();
  const auto fail = [&name](const std::string& why) {
    return MachineFileError({Diagnostic{name, 0, 0, why}});
  };
  const auto system_error = [](int code) { return std::generic_category().message(code); };

  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw fail("cannot read: " + system_error(errno));
  std::string text;
  int read_error = 0;
  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    read_error = errno;
  } else if (S_ISDIR(info.st_mode)) {
    read_error = EISDIR;
  } else {
    char buffer[1 << 16];
    while (true) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        read_error = errno;
        break;
      }
      if (n == 0) break;
      text.append(buffer, static_cast<std::size_t>(n));
      if (text.size() > kMaxMachineFileBytes) {
        ::close(fd);
        throw fail("cannot read: file too large; a machine file is at most " +
                   std::to_string(kMaxMachineFileBytes >> 20) + " MiB");
      }
    }
  }
  ::close(fd);
  if (read_error != 0) throw fail("cannot read: " + system_error(read_error));
  return text;
}

Machine load_machine(const std::filesystem::path& path) { return parse_machine(read_machine_text(path), path.string()); }

Diagnostic diagnostic_at(std::string_view yaml_text, const std::string& file_name, std::string_view key_path, std::string message) {
  Diagnostic d{file_name, 0, 0, std::move(message)};
  auto place = [&d](const YAML::Mark& m) {
    d.line = m.line + 1;
    d.column = m.column + 1;
  };
  try {
    const YAML::Node root = YAML::Load(std::string(yaml_text));
    std::vector<YAML::Node> path{root};  // Node's operator= writes through: keep each step
    std::size_t at = 0;
    while (at < key_path.size()) {
      const std::size_t end = std::min(key_path.find('.', at), key_path.size());
      std::string_view part = key_path.substr(at, end - at);
      at = end + 1;
      std::optional<std::size_t> index;
      if (const auto open = part.find('['); open != std::string_view::npos) {
        index = std::stoul(std::string(part.substr(open + 1)));
        part = part.substr(0, open);
      }
      const YAML::Node node = path.back();  // a handle of its own: push_back moves the vector
      if (!node.IsMap()) break;
      bool found = false;
      for (const auto& entry : node) {
        if (!entry.first.IsScalar() || entry.first.Scalar() != part) continue;
        place(entry.first.Mark());  // the key: where a defaulted value below it belongs
        path.push_back(entry.second);
        found = true;
        break;
      }
      if (!found) break;
      if (index) {
        const YAML::Node sequence = path.back();
        if (!sequence.IsSequence() || *index >= sequence.size()) break;
        path.push_back(sequence[*index]);
        place(path.back().Mark());
      }
      if (at >= key_path.size()) place(path.back().Mark());  // the value itself
    }
  } catch (const std::exception&) {  // a file that parsed once parses again; if not, the file as a whole
  }
  return d;
}

}  // namespace hybridctl::config
