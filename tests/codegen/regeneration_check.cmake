# Regenerates every machine of models/ into WORK_DIR and compares with generated/ byte for byte
# (symforce's compare_or_update_directory, as a ctest). Fails with the files that differ.
file(REMOVE_RECURSE "${WORK_DIR}")
execute_process(
  COMMAND "${CODEGEN}" --clean --models "${SOURCE_DIR}/models" -o "${WORK_DIR}"
  WORKING_DIRECTORY "${SOURCE_DIR}"
  RESULT_VARIABLE result OUTPUT_QUIET ERROR_VARIABLE errors)
if(NOT result EQUAL 0)
  message(FATAL_ERROR "codegen failed (${result}):\n${errors}")
endif()
file(GLOB_RECURSE expected RELATIVE "${SOURCE_DIR}/generated" "${SOURCE_DIR}/generated/*")
file(GLOB_RECURSE actual RELATIVE "${WORK_DIR}" "${WORK_DIR}/*")
list(SORT expected)
list(SORT actual)
set(stale "")
if(NOT expected STREQUAL actual)
  set(stale "file sets differ:\n  committed: ${expected}\n  regenerated: ${actual}\n")
endif()
# COMPARE_CONTENT=OFF (the sanitizer build): the file sets only. GiNaC's automatic evaluation
# picks normal forms (which sign a sum takes, where a numeric factor goes) by hashes seeded
# from the addresses of type-name strings, so a generator built with other flags (ASan's
# RelWithDebInfo against the reference Release) writes −(b − a)·(−0.5) where the reference
# writes (a − b)·0.5, and the temporaries and the canonical operand order of the printer
# (codegen/expression_printer.cc) follow from those forms. Same mathematics, other text (1492
# lines of diff on xcmg_968ev.cc). generated/ is the reference build's output, checked byte
# for byte there (CI).
if(NOT DEFINED COMPARE_CONTENT)
  set(COMPARE_CONTENT ON)
endif()
foreach(file IN LISTS expected)
  if(COMPARE_CONTENT AND EXISTS "${WORK_DIR}/${file}")
    file(SHA256 "${SOURCE_DIR}/generated/${file}" a)
    file(SHA256 "${WORK_DIR}/${file}" b)
    if(NOT a STREQUAL b)
      string(APPEND stale "  differs: generated/${file}\n")
    endif()
  endif()
endforeach()
if(stale)
  message(FATAL_ERROR "generated/ is stale: run `cmake --build build --target regen`\n${stale}")
endif()
message(STATUS "generated/ matches a fresh regeneration")
