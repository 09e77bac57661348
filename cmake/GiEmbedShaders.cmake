# gi_embed_shaders(<target> <function> <dir> [<namespace>])   (namespace defaults to engine)
# Embeds every *.glsl file in <dir> into a generated C++ source added to <target>. The
# generated file defines
#   std::span<const engine::ShaderFile> <namespace>::<function>();
# (declared in <engine/shader_source.h> for the engine), one entry per file: its name (e.g.
# "forward.frag.glsl") and its text. Files are re-embedded when any .glsl changes, so
# editing a shared *_common.glsl include rebuilds its users.
set(_GI_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/GiEmbedShadersScript.cmake)
function(gi_embed_shaders target function dir)
  set(_namespace engine)
  if(ARGC GREATER 3)
    set(_namespace ${ARGV3})
  endif()
  file(GLOB _files CONFIGURE_DEPENDS ${dir}/*.glsl)
  list(SORT _files)
  set(_out ${CMAKE_CURRENT_BINARY_DIR}/${function}_embedded.cpp)
  add_custom_command(
    OUTPUT ${_out}
    COMMAND ${CMAKE_COMMAND} -DOUT=${_out} -DFUNCTION=${function} -DNAMESPACE=${_namespace} -DDIR=${dir} -P ${_GI_EMBED_SCRIPT}
    DEPENDS ${_files} ${_GI_EMBED_SCRIPT}
    COMMENT "Embedding shaders of ${dir}"
    VERBATIM)
  target_sources(${target} PRIVATE ${_out})
endfunction()
