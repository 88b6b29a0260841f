# Warnings as errors for the project's own code. Third-party headers come in through imported
# targets as -isystem, so their warnings do not count.
function(autoshovel_target_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
                                           -Wconversion-null -Werror
                                           # GCC 12 false positive on std::string concatenation
                                           # at -O3 (GCC bug 105329).
                                           -Wno-restrict)
endfunction()

# Generated code: same strictness, minus unused-variable noise that common-subexpression
# elimination can leave in rarely used outputs.
function(autoshovel_generated_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Werror
                                           -Wno-unused-variable -Wno-unused-parameter)
endfunction()
