# flipscope_embed_text(TARGET target FILES a.glsl b.glsl)
# Embeds text files (GLSL) into the target at build time, so the binary works from any
# directory. Each file becomes `extern const std::string_view <symbol>` in the generated header
# `<target>_embedded.h` in namespace flipscope::embedded::<target>, symbol = file name with non-identifier characters replaced by '_'.
# `#include "x.h"` lines inside a shader are resolved later, at run time, by ShaderSource
# from the same embedded set (see gl/ShaderSource.h).
function(flipscope_embed_text)
  cmake_parse_arguments(ARG "" "TARGET" "FILES" ${ARGN})
  set(_out_dir "${CMAKE_CURRENT_BINARY_DIR}/embedded")
  set(_header "${_out_dir}/${ARG_TARGET}_embedded.h")
  set(_source "${_out_dir}/${ARG_TARGET}_embedded.cpp")
  set(_abs_files "")
  foreach(_f IN LISTS ARG_FILES)
    get_filename_component(_abs "${_f}" ABSOLUTE)
    list(APPEND _abs_files "${_abs}")
  endforeach()
  add_custom_command(
    OUTPUT "${_header}" "${_source}"
    COMMAND ${CMAKE_COMMAND} -DNAMESPACE=${ARG_TARGET} -DOUT_HEADER=${_header} -DOUT_SOURCE=${_source}
            "-DFILES=${_abs_files}" -P "${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake"
    DEPENDS ${_abs_files} "${PROJECT_SOURCE_DIR}/cmake/EmbedText.cmake"
    COMMENT "Embedding text files into ${ARG_TARGET}"
    VERBATIM)  # keeps the FILES list one argument
  target_sources(${ARG_TARGET} PRIVATE "${_source}" "${_header}")
  target_include_directories(${ARG_TARGET} PUBLIC "${_out_dir}")
endfunction()
