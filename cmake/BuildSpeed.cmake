# How long a build takes (docs/performance.md, "Build and test times", has the figures and
# their commands):
#   - ccache, where it is installed: a compile it has seen (any clone, any build folder:
#     paths are taken relative to the source tree, the working directory left out) is read
#     back from ~/.cache/ccache instead of compiled.
#   - mold, where it is installed: the links (psysc, the viewer, the LLVM tests and the
#     benchmarks link LLVM's static libraries) take a fraction of ld.bfd's time.
#   - PSYS_UNITY (scripts/test.sh, scripts/demo.sh and scripts/fuzz.sh build with it): each
#     target's sources compiled up to 16 at a time as one translation unit, so the headers
#     they share (the standard library, fmt, LLVM, the ANTLR runtime, our own) are read and
#     their templates instantiated once a batch, not once a file: a cold build in less than
#     half the time. A change recompiles its whole batch, so a build by hand, which is
#     rebuilt file by file, keeps it off. Files whose names would clash with a neighbour's
#     (a file-wide `using namespace`) say SKIP_UNITY_BUILD_INCLUSION where they are listed.
#   - PSYS_DEBUG_INFO: how much debug information RelWithDebInfo and Debug carry. `full`
#     (-g, by default: a build by hand is debugged), `lines` (-g1: file and line in a
#     backtrace, gdb and the sanitizers' reports, and a quarter less compile time: what
#     scripts/test.sh and scripts/demo.sh build), or `none`.

option(PSYS_CCACHE "Compile through ccache where it is installed" ON)
if(PSYS_CCACHE AND NOT CMAKE_CXX_COMPILER_LAUNCHER)
  find_program(PSYS_CCACHE_PROGRAM ccache)
  if(PSYS_CCACHE_PROGRAM)
    set(launcher env CCACHE_BASEDIR=${PROJECT_SOURCE_DIR} CCACHE_NOHASHDIR=1 ${PSYS_CCACHE_PROGRAM})
    set(CMAKE_CXX_COMPILER_LAUNCHER ${launcher})
    set(CMAKE_C_COMPILER_LAUNCHER ${launcher})
  endif()
endif()

option(PSYS_MOLD "Link with mold where it is installed" ON)
if(PSYS_MOLD)
  include(CheckLinkerFlag)
  check_linker_flag(CXX -fuse-ld=mold PSYS_HAVE_MOLD)
  if(PSYS_HAVE_MOLD)
    add_link_options(-fuse-ld=mold)
  endif()
endif()

option(PSYS_UNITY "Compile each target's sources in batches (a unity build)" OFF)
if(PSYS_UNITY)
  set(CMAKE_UNITY_BUILD ON)
  set(CMAKE_UNITY_BUILD_BATCH_SIZE 16)
endif()

set(PSYS_DEBUG_INFO full CACHE STRING "Debug information in RelWithDebInfo and Debug builds: full, lines or none")
set_property(CACHE PSYS_DEBUG_INFO PROPERTY STRINGS full lines none)
if(PSYS_DEBUG_INFO STREQUAL "lines")
  add_compile_options($<$<CONFIG:RelWithDebInfo,Debug>:-g1>)
elseif(PSYS_DEBUG_INFO STREQUAL "none")
  add_compile_options($<$<CONFIG:RelWithDebInfo,Debug>:-g0>)
elseif(NOT PSYS_DEBUG_INFO STREQUAL "full")
  message(FATAL_ERROR "PSYS_DEBUG_INFO is full, lines or none, not `${PSYS_DEBUG_INFO}`")
endif()
