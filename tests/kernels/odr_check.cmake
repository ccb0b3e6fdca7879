# The ODR rule of kernels/README.md, checked on the built library: the per-ISA objects may
# define weak (linker-merged) symbols only inside their own namespace, or the linker could
# hand AVX2 code to a caller that runs on an SSE2-only CPU.
# Usage: cmake -DLIB=<liboctray_kernels.a> -DNM=<nm> -P odr_check.cmake
execute_process(COMMAND ${NM} -C -A ${LIB} OUTPUT_VARIABLE symbols RESULT_VARIABLE status)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "nm failed on ${LIB}")
endif()
string(REPLACE "\n" ";" lines "${symbols}")
set(checked 0)
set(offending "")
foreach(line IN LISTS lines)
  if(line MATCHES "kernels_(avx2|sse41|sse2)\\.cpp\\.o:" AND line MATCHES " [WVu] ")
    math(EXPR checked "${checked} + 1")
    if(NOT line MATCHES "octray::kernels::(avx2_fma|sse4_1|sse2)::" AND
       NOT line MATCHES "DW\\.ref\\.__gxx_personality_v0")
      string(APPEND offending "  ${line}\n")
    endif()
  endif()
endforeach()
if(checked EQUAL 0)
  message(FATAL_ERROR "no weak symbols of the ISA objects found in ${LIB}: check the test")
endif()
if(offending)
  message(FATAL_ERROR "shared weak symbols in the per-ISA kernel objects:\n${offending}")
endif()
message(STATUS "${checked} weak symbols, all in their ISA's namespace")
