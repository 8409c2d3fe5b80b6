# Writes OUT, a C++ source defining skybake::kBuildCommit: the git commit of
# SOURCE_DIR's checkout, or "unknown" when SOURCE_DIR is not the top of a git
# work tree (a release tarball, a copy) or git is missing. Run at every build
# (cmake -P, by the skybake_build_commit target); OUT is rewritten only when
# the commit changed, so an unchanged checkout rebuilds nothing.
#   cmake -DSOURCE_DIR=... -DOUT=... -P build_commit.cmake
set(commit "unknown")
find_program(GIT_EXECUTABLE git)
if(GIT_EXECUTABLE)
  execute_process(COMMAND ${GIT_EXECUTABLE} -C ${SOURCE_DIR} rev-parse --show-toplevel HEAD
                  OUTPUT_VARIABLE lines RESULT_VARIABLE status ERROR_QUIET OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(status EQUAL 0)
    string(REPLACE "\n" ";" lines "${lines}")
    list(GET lines 0 top)
    list(GET lines 1 head)
    # A checkout inside another repository's work tree is not that repository's commit.
    file(REAL_PATH "${top}" top)
    file(REAL_PATH "${SOURCE_DIR}" source)
    if(top STREQUAL source AND head MATCHES "^[0-9a-f]+$")
      set(commit "${head}")
    endif()
  endif()
endif()
string(CONCAT text
  "// Written by cmake/build_commit.cmake at build time: do not edit.\n"
  "#include \"build_commit.h\"\n\n"
  "namespace skybake {\nconst char* const kBuildCommit = \"${commit}\";\n}  // namespace skybake\n")
set(old "")
if(EXISTS "${OUT}")
  file(READ "${OUT}" old)
endif()
if(NOT old STREQUAL text)
  file(WRITE "${OUT}" "${text}")
endif()
