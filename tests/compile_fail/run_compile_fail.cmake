# One compile-fail test: compiles SOURCE with the project's compiler and
# include paths (-fsyntax-only: templates are instantiated, nothing is
# written) and passes only if
#   EXPECT empty:     the compilation succeeds (the control file);
#   EXPECT a regex:   the compilation fails AND its FIRST error line is a
#                     failed static assertion whose message matches EXPECT
#                     (the contract's message comes before anything else the
#                     compiler has to say). GCC writes "static assertion
#                     failed: MSG", clang 14 "static_assert failed due to
#                     requirement '...' "MSG"".
# cmake -DCXX=... -DSTD=-std=c++20 -DINCLUDES="a|b" -DDEFINES="X=1|Y" -DSOURCE=f.cpp
#       [-DEXPECT=regex] -P run_compile_fail.cmake
string(REPLACE "|" ";" includes "${INCLUDES}")
string(REPLACE "|" ";" defines "${DEFINES}")
set(args ${STD} -fsyntax-only)
foreach(dir IN LISTS includes)
  if(dir)
    list(APPEND args "-I${dir}")
  endif()
endforeach()
foreach(def IN LISTS defines)
  if(def)
    list(APPEND args "-D${def}")
  endif()
endforeach()
execute_process(COMMAND ${CXX} ${args} ${SOURCE}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(log "${out}${err}")

if("${EXPECT}" STREQUAL "")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "expected ${SOURCE} to compile; it failed (${rc}):\n${log}")
  endif()
  message(STATUS "compiled, as expected: ${SOURCE}")
  return()
endif()

if(rc EQUAL 0)
  message(FATAL_ERROR "expected ${SOURCE} not to compile (contract: ${EXPECT}); it compiled")
endif()
string(REGEX MATCH "[^\n]*error:[^\n]*" first_error "${log}")
if(NOT first_error MATCHES "static.assert(ion)? failed" OR NOT first_error MATCHES "${EXPECT}")
  message(FATAL_ERROR "${SOURCE} failed to compile, but its first error is not the contract's.\n"
                      "expected (regex): ${EXPECT}\nfirst error: ${first_error}\nfull output:\n${log}")
endif()
string(REGEX MATCHALL "error:" errors "${log}")
list(LENGTH errors n)
message(STATUS "failed to compile, as expected (${n} error(s)); first: ${first_error}")
