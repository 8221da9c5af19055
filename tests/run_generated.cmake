# Programs too large to keep as files, written here and run with psysc: they must simply
# work (long flat chains, deep right-nested chains) or get the nesting error.
#   cmake -DPSYSC=... -DOUT=dir -DKIND=sum|followed_by|conditional|if|nesting -P run_generated.cmake
file(MAKE_DIRECTORY ${OUT})
set(expect "after 2 frames")
set(expect_rc 0)
if(KIND STREQUAL "sum")          # 100,000 terms, one equation
  string(REPEAT " + 1" 100000 terms)
  set(expr "age${terms}")
elseif(KIND STREQUAL "followed_by")  # 10,000 `->` in a row
  string(REPEAT "1 -> " 10000 chain)
  set(expr "${chain}age")
elseif(KIND STREQUAL "conditional")  # 10,000 `?:` nested to the right
  string(REPEAT "age > 1 ? 1 : " 10000 chain)
  set(expr "${chain}age")
elseif(KIND STREQUAL "if")
  string(REPEAT "if age > 1 then 1 else " 10000 chain)
  set(expr "${chain}age")
elseif(KIND STREQUAL "nesting")      # 255 brackets inside the object's braces work; 256 do not
  string(REPEAT "(" 255 open)
  string(REPEAT ")" 255 close)
  set(expr "${open}age${close} + (${open}age${close})")
  set(expect "nesting exceeds the maximum of 256 levels")
  set(expect_rc 1)
endif()
file(WRITE ${OUT}/${KIND}.psys "object o { y = ${expr}; point(vec3(y), white, 1); }\nspawn o;\n")
execute_process(COMMAND ${PSYSC} run --backend interp --quiet --frames 2 ${OUT}/${KIND}.psys
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL expect_rc OR NOT "${out}${err}" MATCHES "${expect}")
  string(SUBSTRING "${out}${err}" 0 2000 shown)
  message(FATAL_ERROR "${KIND}: exit ${rc} (expected ${expect_rc}), output:\n${shown}")
endif()
