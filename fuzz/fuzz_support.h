#pragma once
// Shared by the libFuzzer harnesses: what counts as a finding, and a private folder for
// the files the readers under test insist on opening by path.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <string>

#include "volume/core/error.h"

namespace sslpv::fuzz {

/// Runs `body`; the product's typed input errors are the expected outcome of bad input.
/// Any other exception is a finding: abort() makes libFuzzer keep the input as a crash.
template <class Body>
void expectOnlyInputErrors(Body&& body) {
  try {
    body();
  } catch (const InputError&) {
  } catch (const ResourceError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "FINDING: unexpected exception (not InputError/ResourceError): %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "FINDING: unexpected exception of a non-std type\n");
    std::abort();
  }
}

/// A property the product promises failed for this input.
[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "FINDING: %s\n", what.c_str());
  std::abort();
}

/// This process's own scratch folder (created on first use, removed at exit), so that
/// parallel fuzzer jobs never share files.
const std::filesystem::path& scratchDir();

/// Writes `size` bytes to scratchDir()/name and returns the path.
std::filesystem::path writeScratchFile(const std::string& name, const std::uint8_t* data, std::size_t size);

/// A small valid material set (sigma_t, sigma_s, g on a 6³ block, 1 mm voxels) at `file`,
/// what the scene harnesses' "vdb" keys name.
void writeSmallMaterialSet(const std::filesystem::path& file);

/// A closed unit cube in OBJ text, what the scene harnesses' "path" keys name.
const char* smallClosedObj();

}  // namespace sslpv::fuzz
