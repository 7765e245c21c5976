#include "volume/core/strict_json.h"

#include <cmath>
#include <cstdio>

#include "volume/core/error.h"
#include "volume/core/input_file.h"

namespace sslpv {

namespace fs = std::filesystem;
using nlohmann::json;

std::string printable(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
      out += escaped;
    } else {
      out += c;
    }
  }
  return out;
}

std::string childPath(const std::string& path, std::string_view key) {
  return path.empty() ? printable(key) : path + "." + printable(key);
}

std::string indexPath(const std::string& path, std::size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

std::string formatNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", value);
  return text;
}

std::string quotedList(std::initializer_list<const char*> names) {
  std::string out;
  for (const char* name : names) {
    if (!out.empty()) out += ", ";
    out += '"';
    out += name;
    out += '"';
  }
  return out;
}

std::string describeType(const json& value) {
  switch (value.type()) {
    case json::value_t::null: return "null";
    case json::value_t::object: return "an object";
    case json::value_t::array: return "an array";
    case json::value_t::string: return "a string";
    case json::value_t::boolean: return "a boolean";
    case json::value_t::binary: return "binary data";
    case json::value_t::discarded: return "nothing";
    default: return "a number";
  }
}

std::string readInputFile(const fs::path& file, const char* what) {
  return readRegularFile(file, what, kMaxJsonInputBytes);
}

bool JsonPathTracker::operator()(int /*depth*/, json::parse_event_t event, json& parsed) {
  switch (event) {
    case json::parse_event_t::object_start: frames_->push_back({false, 0, {}, false, {}}); break;
    case json::parse_event_t::array_start: frames_->push_back({true, 0, {}, false, {}}); break;
    case json::parse_event_t::key: {
      Frame& top = frames_->back();
      top.key = parsed.get<std::string>();
      top.hasKey = true;
      if (!top.keys.insert(top.key).second) throw InputError(file_.string() + ": " + path() + ": duplicate key");
      break;
    }
    case json::parse_event_t::object_end:
    case json::parse_event_t::array_end:
      frames_->pop_back();
      completeValue();
      break;
    case json::parse_event_t::value: completeValue(); break;
  }
  return true;
}

std::string JsonPathTracker::path() const {
  std::string out;
  for (const Frame& frame : *frames_) {
    if (frame.isArray)
      out = indexPath(out, frame.index);
    else if (frame.hasKey)
      out = childPath(out, frame.key);
  }
  return out;
}

void JsonPathTracker::completeValue() {
  if (frames_->empty()) return;
  Frame& top = frames_->back();
  if (top.isArray)
    ++top.index;
  else
    top.hasKey = false;
}

void StrictJsonReader::fail(const std::string& path, const std::string& reason) const {
  throw InputError(file_.string() + ": " + (path.empty() ? "" : path + ": ") + reason);
}

void StrictJsonReader::requireObject(const json& value, const std::string& path) const {
  if (!value.is_object()) fail(path, "expected an object, got " + describeType(value));
}

void StrictJsonReader::allowOnly(const json& object, const std::string& path,
                                 std::initializer_list<const char*> accepted) const {
  for (const auto& item : object.items()) {
    bool known = false;
    for (const char* name : accepted) known = known || item.key() == name;
    if (!known) fail(childPath(path, item.key()), "unknown key (accepted keys: " + quotedList(accepted) + ")");
  }
}

const json* StrictJsonReader::optional(const json& object, const char* key) const {
  auto it = object.find(key);
  return it == object.end() ? nullptr : &*it;
}

const json& StrictJsonReader::required(const json& object, const std::string& path, const char* key) const {
  auto it = object.find(key);
  if (it == object.end()) fail(path, std::string("missing required key \"") + key + "\"");
  return *it;
}

double StrictJsonReader::number(const json& value, const std::string& path) const {
  if (!value.is_number()) fail(path, "expected a number, got " + describeType(value));
  const double result = value.get<double>();
  if (!std::isfinite(result)) fail(path, "expected a finite number");
  return result;
}

int StrictJsonReader::integer(const json& value, const std::string& path, int lo, int hi) const {
  const std::string expected =
      "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!value.is_number()) fail(path, expected + ", got " + describeType(value));
  const double result = value.get<double>();
  if (result != std::floor(result)) fail(path, expected + ", got " + formatNumber(result));
  if (!(result >= lo && result <= hi)) fail(path, expected + ", got " + formatNumber(result));
  return static_cast<int>(result);
}

std::string StrictJsonReader::string(const json& value, const std::string& path) const {
  if (!value.is_string()) fail(path, "expected a string, got " + describeType(value));
  return value.get<std::string>();
}

void StrictJsonReader::requireTriple(const json& value, const std::string& path, const std::string& expected) const {
  if (!value.is_array() || value.size() != 3) {
    fail(path, expected + ", got " +
                   (value.is_array() ? "an array of " + std::to_string(value.size()) : describeType(value)));
  }
}

glm::dvec3 StrictJsonReader::vec3(const json& value, const std::string& path, const char* what) const {
  const std::string expected = std::string("expected an array of 3 ") + what;
  requireTriple(value, path, expected);
  glm::dvec3 result;
  for (int i = 0; i < 3; ++i) {
    const json& element = value[std::size_t(i)];
    if (!element.is_number() || !std::isfinite(element.get<double>()))
      fail(indexPath(path, std::size_t(i)), expected + ", got " + describeType(element));
    result[i] = element.get<double>();
  }
  return result;
}

glm::dvec3 StrictJsonReader::vec3OfNumbers(const json& value, const std::string& path) const {
  requireTriple(value, path, "expected an array of 3 numbers");
  glm::dvec3 result;
  for (int i = 0; i < 3; ++i) result[i] = number(value[std::size_t(i)], indexPath(path, std::size_t(i)));
  return result;
}

}  // namespace sslpv
