# cmake -DINPUT=x.spv -DOUTPUT=x.spv.h -DNAME=kXSpv -P spv_to_header.cmake
# Writes a SPIR-V binary as `const uint32_t NAME[]` (SPIR-V words are
# little-endian in the file and on every machine skybake builds for).
file(READ ${INPUT} hex HEX)
string(LENGTH "${hex}" length)
math(EXPR remainder "${length} % 8")
if(length EQUAL 0 OR NOT remainder EQUAL 0)
  message(FATAL_ERROR "${INPUT} is not a whole number of 32-bit SPIR-V words")
endif()
string(REGEX REPLACE "(..)(..)(..)(..)" "0x\\4\\3\\2\\1," words "${hex}")
string(REGEX REPLACE "((0x........,){8})" "\\1\n  " words "${words}")
file(WRITE ${OUTPUT} "#pragma once\n#include <cstdint>\n// ${INPUT}\nconst uint32_t ${NAME}[] = {\n  ${words}\n};\n")
