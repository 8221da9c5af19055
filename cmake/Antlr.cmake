# Generates a C++ parser from a .g4 grammar with Debian's antlr4 tool (4.7.2), whose
# output builds against the 4.9 runtime. The runtime's own antlr4_generate() helper
# expects a downloaded jar, so we call the tool directly.
find_package(antlr4-runtime REQUIRED CONFIG)
find_program(ANTLR4_TOOL antlr4 REQUIRED)

function(psys_antlr_generate target grammar_file)
  get_filename_component(name ${grammar_file} NAME_WE)
  set(out ${CMAKE_CURRENT_BINARY_DIR}/generated)
  set(sources
    ${out}/${name}Lexer.cpp ${out}/${name}Parser.cpp
    ${out}/${name}Visitor.cpp ${out}/${name}BaseVisitor.cpp)
  add_custom_command(
    OUTPUT ${sources}
    COMMAND ${ANTLR4_TOOL} -Dlanguage=Cpp -visitor -no-listener -package psys::grammar
            -o ${out} -Xexact-output-dir ${grammar_file}
    DEPENDS ${grammar_file}
    COMMENT "Generating the ${name} parser with antlr4"
    VERBATIM)
  add_library(${target} STATIC ${sources})
  # Generated code and the runtime headers are not ours: no warnings, system includes.
  target_include_directories(${target} SYSTEM PUBLIC ${out} ${ANTLR4_INCLUDE_DIR})
  target_compile_options(${target} PRIVATE -w -fno-char8_t)
  target_compile_options(${target} PUBLIC -Wno-attributes)
  target_link_libraries(${target} PUBLIC antlr4_shared)
  set_target_properties(${target} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()
