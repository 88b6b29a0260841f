# Generated code is a function of its description alone (issue 39): the machines of models/ are
# generated three ways — all together in the order of --models, in the reverse order after an
# extra machine (a renamed copy of the first), and each alone in its own generator run — and
# every machine's files must be byte-identical across the three.
file(GLOB_RECURSE descriptions "${SOURCE_DIR}/models/*.yaml")
list(FILTER descriptions EXCLUDE REGEX "/(materials|scenarios|prediction|segmentation)/")
list(SORT descriptions)
list(LENGTH descriptions count)
if(count LESS 2)
  message(FATAL_ERROR "expected at least two machine descriptions under models/, got ${count}")
endif()
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

function(run_codegen output)
  execute_process(
    COMMAND "${CODEGEN}" --materials "${SOURCE_DIR}/models/materials" -o "${output}" ${ARGN}
    WORKING_DIRECTORY "${SOURCE_DIR}"
    RESULT_VARIABLE result OUTPUT_QUIET ERROR_VARIABLE errors)
  if(NOT result EQUAL 0)
    message(FATAL_ERROR "codegen failed (${result}) for ${ARGN}:\n${errors}")
  endif()
endfunction()

# 1. All together, sorted.
run_codegen("${WORK_DIR}/together" ${descriptions})

# 2. Reversed, after an extra machine built first in the same process.
list(GET descriptions 0 first)
file(READ "${first}" text)
string(REGEX REPLACE "\nname: [a-z0-9_]+" "\nname: zz_extra_machine" text "${text}")
set(extra "${WORK_DIR}/zz_extra_machine.yaml")
file(WRITE "${extra}" "${text}")
set(reversed ${descriptions})
list(REVERSE reversed)
run_codegen("${WORK_DIR}/reversed" "${extra}" ${reversed})

# 3. Each alone.
set(names "")
foreach(description IN LISTS descriptions)
  file(STRINGS "${description}" name_line REGEX "^name: ")
  string(REGEX REPLACE "^name: *([a-z0-9_]+).*" "\\1" name "${name_line}")
  list(APPEND names "${name}")
  run_codegen("${WORK_DIR}/alone" "${description}")
endforeach()

set(differences "")
foreach(name IN LISTS names)
  foreach(suffix IN ITEMS cc h)
    set(file "${name}/${name}.${suffix}")
    file(SHA256 "${WORK_DIR}/together/${file}" a)
    file(SHA256 "${WORK_DIR}/reversed/${file}" b)
    file(SHA256 "${WORK_DIR}/alone/${file}" c)
    if(NOT a STREQUAL b OR NOT a STREQUAL c)
      string(APPEND differences "  ${file}: together ${a}, reversed ${b}, alone ${c}\n")
    endif()
  endforeach()
endforeach()
if(differences)
  message(FATAL_ERROR "generated code depends on what else was generated:\n${differences}")
endif()
message(STATUS "${count} machines: byte-identical together, reversed after another, and alone")
