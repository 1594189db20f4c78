#pragma once
// How `emoface export` lays data into a glTF model's one binary buffer: buffer
// views, dense and sparse accessors, PNG images. Each helper appends to
// buffer 0 (4-byte aligned) and returns the index it made.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace emoface::apps::gltf {

// `bytes` as a new buffer view (target 0: none, e.g. images, animation data).
int add_view(tinygltf::Model& m, const void* bytes, std::size_t size, int target = 0);

// A dense float accessor of `components` per element; `bounds`: with min/max
// (glTF requires them for POSITION).
int add_floats(tinygltf::Model& m, const std::vector<float>& data, int type, int components, bool bounds,
               int target = TINYGLTF_TARGET_ARRAY_BUFFER);

// A morph target's POSITION displacements (3 per vertex) as a sparse accessor:
// only the vertices that move (a component above `negligible` in size) are
// stored, the others read as 0. Most targets move a small region of the face,
// so this is a fraction of the dense size. Bounds over all vertices.
int add_sparse_vec3(tinygltf::Model& m, const std::vector<float>& data, float negligible);

// Unsigned indices (16-bit where they fit) as an element-array accessor.
int add_indices(tinygltf::Model& m, const std::vector<std::uint32_t>& idx, int vertex_count);

// An RGBA8 image (rows top first) as a PNG in a buffer view; the image's index.
int add_png(tinygltf::Model& m, const std::string& name, int width, int height, const std::uint8_t* rgba);

// A texture sampling image `image` with linear filtering and repeat wrapping
// (the glTF default); its index.
int add_texture(tinygltf::Model& m, int image);

}  // namespace emoface::apps::gltf
