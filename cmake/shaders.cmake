# Compiles every GLSL stage under shaders/ to SPIR-V with glslc, at build time. glslc writes
# each stage's includes to a depfile, so editing one include rebuilds only the stages that use it.
# Each stage gets SHADEL_SHADER_ID (its index in the generated table shader_table.inc) so
# shader asserts can name the file they came from.
function(shadel_compile_shaders target source_dir binary_dir)
  file(GLOB_RECURSE stages CONFIGURE_DEPENDS
       ${source_dir}/*.vert ${source_dir}/*.frag ${source_dir}/*.comp
       ${source_dir}/*.mesh ${source_dir}/*.task)
  list(SORT stages)
  set(outputs "")
  set(table "")
  set(id 1)
  # Debug builds compile shaders with SHADEL_DEBUG_SHADERS: extra checks and loud colours.
  set(debug_flags "")
  if(CMAKE_BUILD_TYPE STREQUAL "Debug")
    set(debug_flags -DSHADEL_DEBUG_SHADERS=1)
  endif()
  foreach(stage ${stages})
    file(RELATIVE_PATH rel ${source_dir} ${stage})
    string(REPLACE "/" "_" flat ${rel})
    set(spv ${binary_dir}/${flat}.spv)
    add_custom_command(
      OUTPUT ${spv}
      COMMAND ${GLSLC} --target-env=vulkan1.3 -O -g -I ${source_dir} -DSHADEL_SHADER_ID=${id} ${debug_flags}
              -Werror -MD -MF ${spv}.d -o ${spv} ${stage}
      DEPENDS ${stage}
      DEPFILE ${spv}.d
      COMMENT "glslc ${rel}"
      VERBATIM)
    list(APPEND outputs ${spv})
    string(APPEND table "{${id}, \"shaders/${rel}\"},\n")
    math(EXPR id "${id} + 1")
  endforeach()
  file(WRITE ${binary_dir}/shader_table.inc.tmp "${table}")
  configure_file(${binary_dir}/shader_table.inc.tmp ${binary_dir}/shader_table.inc COPYONLY)
  add_custom_target(${target} ALL DEPENDS ${outputs})
endfunction()
