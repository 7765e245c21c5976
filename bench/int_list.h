#pragma once
// "32,64" command-line lists of the benchmark programs (--grid).
#include <string>
#include <vector>

namespace sslpv::bench {

/// The comma-separated integers of `list`; std::invalid_argument on a non-number.
inline std::vector<int> parseIntList(const std::string& list) {
  std::vector<int> values;
  for (std::size_t at = 0; at != std::string::npos;) {
    const std::size_t comma = list.find(',', at);
    values.push_back(std::stoi(list.substr(at, comma == std::string::npos ? comma : comma - at)));
    at = comma == std::string::npos ? comma : comma + 1;
  }
  return values;
}

}  // namespace sslpv::bench
