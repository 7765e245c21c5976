#pragma once
// Strict JSON input shared by the scene (volume/scene/scene.cpp) and stroke files
// (editor/stroke_io.cpp): every failure is one InputError line "<file>: <key path>: <reason>"
// with key paths like "lights[1].position[2]"; unknown and duplicated keys, wrong types,
// missing required keys, NaN and Inf are errors, never silently ignored or defaulted.
#include <cstddef>
#include <filesystem>
#include <glm/vec3.hpp>
#include <initializer_list>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace sslpv {

/// `text` with control characters written as \u00XX: keys and strings are echoed into
/// one-line messages, which a JSON "\n" in a key must not break.
std::string printable(std::string_view text);

/// Key path of `key` in the object at `path` ("" is the top level): "camera.width".
std::string childPath(const std::string& path, std::string_view key);

/// Key path of element `index` of the array at `path`: "lights[2]".
std::string indexPath(const std::string& path, std::size_t index);

/// A number as messages show it (%.9g).
std::string formatNumber(double value);

/// "\"a\", \"b\"" for "accepted keys: ..." messages.
std::string quotedList(std::initializer_list<const char*> names);

/// "an object", "a string", ... for "expected X, got Y" messages.
std::string describeType(const nlohmann::json& value);

/// The whole content of an input file. Throws InputError
/// "<file>: cannot read <what> (<reason>)", e.g. what = "scene file".
std::string readInputFile(const std::filesystem::path& file, const char* what);

/// Parser callback for nlohmann::json::parse. nlohmann keeps the last of two equal keys
/// silently, which would hide a typo like a second "steps": a duplicated key throws
/// InputError "<file>: <key path>: duplicate key". It also follows the parser, so that
/// path() names where a syntax error (NaN, a stray token) occurred.
class JsonPathTracker {
 public:
  explicit JsonPathTracker(std::filesystem::path file) : file_(std::move(file)) {}

  bool operator()(int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed);

  /// The key path of the value being parsed ("" at the top level).
  std::string path() const;

 private:
  struct Frame {
    bool isArray;
    std::size_t index;  // arrays: elements completed so far
    std::string key;    // objects: the key being parsed
    bool hasKey;        // objects: `key` names a value not yet complete
    std::set<std::string> keys;
  };

  void completeValue();

  std::filesystem::path file_;
  // Shared: nlohmann copies the callback, the caller keeps a copy to ask for the path.
  std::shared_ptr<std::vector<Frame>> frames_ = std::make_shared<std::vector<Frame>>();
};

/// Reads values out of a parsed document; every failure is an InputError naming the file
/// and the key path given by the caller.
class StrictJsonReader {
 public:
  explicit StrictJsonReader(std::filesystem::path file) : file_(std::move(file)) {}

  const std::filesystem::path& file() const { return file_; }

  /// Throws InputError "<file>: <path>: <reason>" ("<file>: <reason>" for path "").
  [[noreturn]] void fail(const std::string& path, const std::string& reason) const;

  void requireObject(const nlohmann::json& value, const std::string& path) const;

  /// Strictness: a misspelt key must not be ignored silently.
  void allowOnly(const nlohmann::json& object, const std::string& path,
                 std::initializer_list<const char*> accepted) const;

  /// The value of `key`, or null when absent.
  const nlohmann::json* optional(const nlohmann::json& object, const char* key) const;
  const nlohmann::json& required(const nlohmann::json& object, const std::string& path, const char* key) const;

  /// A finite number.
  double number(const nlohmann::json& value, const std::string& path) const;
  /// A number with an integral value in [lo, hi].
  int integer(const nlohmann::json& value, const std::string& path, int lo, int hi) const;
  std::string string(const nlohmann::json& value, const std::string& path) const;

  /// [x, y, z] of finite numbers. A wrong shape, or an element that is not a finite number
  /// (named by its index), fails with "expected an array of 3 <what>, got ...".
  glm::dvec3 vec3(const nlohmann::json& value, const std::string& path, const char* what = "numbers") const;
  /// [x, y, z] whose elements are read by number(): a wrong shape fails like vec3(), a bad
  /// element with number()'s message at its index.
  glm::dvec3 vec3OfNumbers(const nlohmann::json& value, const std::string& path) const;

  /// The value of the string naming one of `options`; an unknown name fails with
  /// "unknown <what> \"name\" (accepted: \"a\", \"b\")".
  template <class Enum>
  Enum choice(const nlohmann::json& value, const std::string& path, const char* what,
              std::initializer_list<std::pair<const char*, Enum>> options) const {
    const std::string text = string(value, path);
    std::string accepted;
    for (const auto& [name, option] : options) {
      if (text == name) return option;
      accepted += std::string(accepted.empty() ? "" : ", ") + "\"" + name + "\"";
    }
    fail(path, "unknown " + std::string(what) + " \"" + printable(text) + "\" (accepted: " + accepted + ")");
  }

 private:
  void requireTriple(const nlohmann::json& value, const std::string& path, const std::string& expected) const;

  std::filesystem::path file_;
};

}  // namespace sslpv
