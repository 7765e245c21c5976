#include "volume/scene/scene_file_edit.h"

#include <cerrno>
#include <fstream>
#include <nlohmann/json.hpp>

#include "volume/core/error.h"
#include "volume/scene/scene.h"
#include "volume/core/strict_json.h"

namespace sslpv {
namespace {

namespace fs = std::filesystem;

/// A byte-level walker over JSON text the caller has already validated with a parser;
/// it only needs to find where values start and end.
class JsonScanner {
 public:
  explicit JsonScanner(const std::string& text) : text_(text) {}

  std::size_t skipSpace(std::size_t at) const {
    while (at < text_.size() && (text_[at] == ' ' || text_[at] == '\t' || text_[at] == '\n' || text_[at] == '\r'))
      ++at;
    return at;
  }

  /// One past the end of the value starting at `at` (no leading space).
  std::size_t valueEnd(std::size_t at) const {
    const char c = text_[at];
    if (c == '"') return stringEnd(at);
    if (c == '{' || c == '[') {
      const char close = c == '{' ? '}' : ']';
      std::size_t i = skipSpace(at + 1);
      if (text_[i] == close) return i + 1;
      for (;;) {
        if (c == '{') i = skipSpace(stringEnd(i)) + 1;  // key, then ':'
        i = skipSpace(valueEnd(skipSpace(i)));
        if (text_[i] == close) return i + 1;
        i = skipSpace(i + 1);  // ','
      }
    }
    // Numbers and the literals true, false, null.
    while (at < text_.size() && std::string(",}] \t\r\n").find(text_[at]) == std::string::npos) ++at;
    return at;
  }

  std::size_t stringEnd(std::size_t at) const {
    for (std::size_t i = at + 1; i < text_.size(); ++i) {
      if (text_[i] == '\\') ++i;
      else if (text_[i] == '"') return i + 1;
    }
    return text_.size();
  }

  struct Member {
    std::size_t keyStart = 0, valueStart = 0, valueEnd = 0;
  };
  struct Lookup {
    bool found = false;
    Member member;        ///< the key's member when found
    bool empty = true;    ///< the object has no members
    Member last;          ///< the last member when not empty
    std::size_t lastGap = 0;  ///< where the whitespace before the last member's key starts
    std::size_t close = 0;    ///< the closing brace
  };

  /// Finds `key` among the members of the object starting at `at` ('{').
  Lookup find(std::size_t at, const std::string& key) const {
    Lookup result;
    std::size_t i = skipSpace(at + 1);
    std::size_t gap = at + 1;
    while (text_[i] != '}') {
      Member m;
      m.keyStart = i;
      const std::size_t keyEnd = stringEnd(i);
      m.valueStart = skipSpace(skipSpace(keyEnd) + 1);
      m.valueEnd = valueEnd(m.valueStart);
      const std::string name = nlohmann::json::parse(text_.substr(i, keyEnd - i)).get<std::string>();
      if (name == key && !result.found) {
        result.found = true;
        result.member = m;
      }
      result.empty = false;
      result.last = m;
      result.lastGap = gap;
      i = skipSpace(m.valueEnd);
      if (text_[i] == ',') {
        gap = i + 1;
        i = skipSpace(i + 1);
      }
    }
    result.close = i;
    return result;
  }

 private:
  const std::string& text_;
};

}  // namespace

std::string spliceJsonValue(const std::string& text, const std::vector<std::string>& keyPath,
                            const std::string& valueJson, const fs::path& file) {
  nlohmann::json parsed;
  try {
    parsed = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception&) {
    throw InputError(file.string() + ": not valid JSON, so it cannot be updated in place");
  }
  if (!parsed.is_object()) throw InputError(file.string() + ": expected a JSON object at the top level");
  if (keyPath.empty()) throw InputError(file.string() + ": no key to update");

  const JsonScanner scan(text);
  std::size_t object = scan.skipSpace(0);
  std::string path;
  for (std::size_t k = 0; k + 1 < keyPath.size(); ++k) {
    path = childPath(path, keyPath[k]);
    const JsonScanner::Lookup found = scan.find(object, keyPath[k]);
    if (!found.found) throw InputError(file.string() + ": " + path + ": missing, so it cannot be updated in place");
    if (text[found.member.valueStart] != '{')
      throw InputError(file.string() + ": " + path + ": expected an object");
    object = found.member.valueStart;
  }
  const std::string& key = keyPath.back();
  const JsonScanner::Lookup found = scan.find(object, key);
  if (found.found)
    return text.substr(0, found.member.valueStart) + valueJson + text.substr(found.member.valueEnd);

  const std::string keyJson = nlohmann::json(key).dump();
  if (found.empty) return text.substr(0, object + 1) + keyJson + ": " + valueJson + text.substr(object + 1);
  // Laid out like the last member: the same whitespace before the key (a newline and its
  // indentation, or a single space) and the same spelling between key and value.
  std::string gap = text.substr(found.lastGap, found.last.keyStart - found.lastGap);
  // A lone member written tight against its brace ({"base": ...}) has no gap to copy.
  if (gap.empty()) gap = " ";
  const std::size_t lastKeyEnd = scan.stringEnd(found.last.keyStart);
  const std::string colon = text.substr(lastKeyEnd, found.last.valueStart - lastKeyEnd);
  return text.substr(0, found.last.valueEnd) + "," + gap + keyJson + colon + valueJson +
         text.substr(found.last.valueEnd);
}

std::string scenePathValue(const fs::path& sceneFile, const fs::path& target) {
  std::error_code error;
  const fs::path folder = fs::absolute(sceneFile, error).parent_path();
  const fs::path absolute = fs::absolute(target, error).lexically_normal();
  fs::path relative = absolute.lexically_relative(folder.lexically_normal());
  if (relative.empty()) relative = absolute;
  return relative.generic_string();
}

AtomicOutput sceneTextOutput(const fs::path& sceneFile, std::string text) {
  return {sceneFile, [sceneFile, text = std::move(text)](const fs::path& temp) {
            std::ofstream out(temp, std::ios::binary);
            out << text;
            out.close();
            if (!out) throwWriteFailed(sceneFile, errno);
          }};
}

std::string sceneTextNamingVdb(const fs::path& sceneFile, const std::string& original, const fs::path& vdb) {
  const std::string text =
      spliceJsonValue(original, {"material", "vdb"}, nlohmann::json(scenePathValue(sceneFile, vdb)).dump(), sceneFile);
  parseScene(text, sceneFile);
  return text;
}

}  // namespace sslpv
