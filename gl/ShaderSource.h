// ShaderSource: complete GLSL sources from the shaders embedded in flipscope_gl at build time
// (every <folder>/glsl of the tree; see cmake/FlipscopeEmbed.cmake), so the binary needs no
// shader files at run time.
#pragma once

#include <string>
#include <string_view>

namespace flipscope::gl {

/// The embedded file `fileName` (a basename, e.g. "Raycast.comp") as a complete compute-shader
/// source: "#version 450 core\n#define FS_FUNC\n#define FS_INOUT(T) inout T\n" (see
/// core/GlslShared.h), then `defines`
/// (lines such as "#define FS_KERNEL rofDual"), then the file
/// with every `#include "Name.glsl"` line replaced by that embedded file, found by basename
/// (a path before it is ignored), recursively. Each file is pasted at most once; a repeated
/// include becomes a comment. Throws std::runtime_error naming an unknown file or include.
std::string shaderSource(std::string_view fileName, std::string_view defines = {});

}  // namespace flipscope::gl
