# cmake -DSPV=<file.spv> -DOUT=<file.cpp> -DSYMBOL=<name> -P embed_spirv.cmake
# Writes a .cpp defining sslpv::spirv::<SYMBOL>() over the SPIR-V words of SPV.
file(READ ${SPV} hex HEX)
string(LENGTH "${hex}" hex_length)
math(EXPR remainder "${hex_length} % 8")
if(hex_length EQUAL 0 OR NOT remainder EQUAL 0)
  message(FATAL_ERROR "${SPV} is not SPIR-V (size is not a multiple of 4 bytes)")
endif()
string(SUBSTRING "${hex}" 0 8 magic)
if(NOT magic STREQUAL "03022307")
  message(FATAL_ERROR "${SPV} is not little-endian SPIR-V (magic ${magic})")
endif()
# SPIR-V words are little-endian on disk: bytes b0 b1 b2 b3 form the word 0xb3b2b1b0.
string(REGEX REPLACE "(..)(..)(..)(..)" "0x\\4\\3\\2\\1u," words "${hex}")
string(REGEX REPLACE "(0x[0-9a-f]+u,0x[0-9a-f]+u,0x[0-9a-f]+u,0x[0-9a-f]+u,0x[0-9a-f]+u,0x[0-9a-f]+u,0x[0-9a-f]+u,0x[0-9a-f]+u,)"
       "\\1\n  " words "${words}")
file(WRITE ${OUT} "// Generated from ${SPV} by shaders/cmake/embed_spirv.cmake: do not edit.
#include \"shaders/spirv_library.h\"

namespace sslpv::spirv {
namespace {
const std::uint32_t kWords[] = {
  ${words}
};
}  // namespace

SpirvCode ${SYMBOL}() { return {kWords, sizeof(kWords) / sizeof(kWords[0])}; }

}  // namespace sslpv::spirv
")
