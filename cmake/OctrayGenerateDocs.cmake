# Run at build time (tools/CMakeLists.txt, target octray_docs) with the octray just built:
#   cmake -DOCTRAY_EXE=.../octray -DOUT_DIR=.../share -P OctrayGenerateDocs.cmake
# Writes, laid out as they are installed (cmake/OctrayInstall.cmake):
#   OUT_DIR/man/man1/octray.1, octray-<command>.1     `octray man --directory`
#   OUT_DIR/bash-completion/completions/octray        `octray completion bash`
#   OUT_DIR/zsh/vendor-completions/_octray            `octray completion zsh`
# All of them come from the option definitions the parser uses, so they cannot drift.
foreach(var OCTRAY_EXE OUT_DIR)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "OctrayGenerateDocs.cmake: -D${var}=... is required")
  endif()
endforeach()

# Pages of commands that no longer exist must not linger.
file(REMOVE_RECURSE ${OUT_DIR}/man/man1)
execute_process(COMMAND ${OCTRAY_EXE} man --directory ${OUT_DIR}/man/man1
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "octray man --directory failed (${status}): ${err}")
endif()

foreach(shell bash zsh)
  if(shell STREQUAL "bash")
    set(file ${OUT_DIR}/bash-completion/completions/octray)
  else()
    set(file ${OUT_DIR}/zsh/vendor-completions/_octray)
  endif()
  get_filename_component(dir ${file} DIRECTORY)
  file(MAKE_DIRECTORY ${dir})
  execute_process(COMMAND ${OCTRAY_EXE} completion ${shell}
    RESULT_VARIABLE status OUTPUT_FILE ${file}.tmp ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    file(REMOVE ${file}.tmp)
    message(FATAL_ERROR "octray completion ${shell} failed (${status}): ${err}")
  endif()
  file(RENAME ${file}.tmp ${file})
endforeach()
