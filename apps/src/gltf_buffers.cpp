#include "gltf_buffers.h"

#include <algorithm>
#include <cmath>

#include <stb_image_write.h>

#include "emoface/common/error.h"

namespace emoface::apps::gltf {

int add_view(tinygltf::Model& m, const void* bytes, std::size_t size, int target) {
    auto& buf = m.buffers.at(0).data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = size;
    if (target) v.target = target;
    buf.insert(buf.end(), static_cast<const unsigned char*>(bytes), static_cast<const unsigned char*>(bytes) + size);
    m.bufferViews.push_back(v);
    return static_cast<int>(m.bufferViews.size()) - 1;
}

namespace {

void set_bounds(tinygltf::Accessor& acc, const std::vector<float>& data, int components) {
    acc.minValues.assign(components, 1e30);
    acc.maxValues.assign(components, -1e30);
    for (std::size_t i = 0; i < data.size(); ++i) {
        const int c = static_cast<int>(i % components);
        // glTF bounds are the float values themselves.
        acc.minValues[c] = std::min(acc.minValues[c], static_cast<double>(data[i]));
        acc.maxValues[c] = std::max(acc.maxValues[c], static_cast<double>(data[i]));
    }
}

int push(tinygltf::Model& m, tinygltf::Accessor acc) {
    m.accessors.push_back(std::move(acc));
    return static_cast<int>(m.accessors.size()) - 1;
}

}  // namespace

int add_floats(tinygltf::Model& m, const std::vector<float>& data, int type, int components, bool bounds, int target) {
    tinygltf::Accessor acc;
    acc.bufferView = add_view(m, data.data(), data.size() * sizeof(float), target);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    acc.type = type;
    acc.count = data.size() / components;
    if (bounds) set_bounds(acc, data, components);
    return push(m, std::move(acc));
}

int add_sparse_vec3(tinygltf::Model& m, const std::vector<float>& data, float negligible) {
    const std::size_t n = data.size() / 3;
    std::vector<std::uint32_t> moved;
    std::vector<float> values;
    for (std::size_t v = 0; v < n; ++v) {
        const float* d = &data[3 * v];
        if (std::max({std::abs(d[0]), std::abs(d[1]), std::abs(d[2])}) <= negligible) continue;
        moved.push_back(static_cast<std::uint32_t>(v));
        values.insert(values.end(), d, d + 3);
    }
    if (moved.empty()) {  // glTF's sparse count is at least 1: one vertex, unmoved
        moved.push_back(0);
        values.assign(3, 0.0f);
    }
    tinygltf::Accessor acc;
    acc.bufferView = -1;  // all zeros but the sparse entries
    acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    acc.type = TINYGLTF_TYPE_VEC3;
    acc.count = n;
    std::vector<float> stored(n * 3, 0.0f);
    for (std::size_t i = 0; i < moved.size(); ++i)
        std::copy_n(&values[3 * i], 3, &stored[3 * std::size_t(moved[i])]);
    set_bounds(acc, stored, 3);
    acc.sparse.isSparse = true;
    acc.sparse.count = static_cast<int>(moved.size());
    if (n <= 65536) {
        std::vector<std::uint16_t> idx(moved.begin(), moved.end());
        acc.sparse.indices.bufferView = add_view(m, idx.data(), idx.size() * 2);
        acc.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
        acc.sparse.indices.bufferView = add_view(m, moved.data(), moved.size() * 4);
        acc.sparse.indices.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    acc.sparse.indices.byteOffset = 0;
    acc.sparse.values.bufferView = add_view(m, values.data(), values.size() * sizeof(float));
    acc.sparse.values.byteOffset = 0;
    return push(m, std::move(acc));
}

int add_indices(tinygltf::Model& m, const std::vector<std::uint32_t>& idx, int vertex_count) {
    tinygltf::Accessor acc;
    acc.type = TINYGLTF_TYPE_SCALAR;
    acc.count = idx.size();
    if (vertex_count <= 65535) {  // 65535 itself is the primitive restart value
        std::vector<std::uint16_t> small(idx.begin(), idx.end());
        acc.bufferView = add_view(m, small.data(), small.size() * 2, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    } else {
        acc.bufferView = add_view(m, idx.data(), idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    }
    return push(m, std::move(acc));
}

int add_png(tinygltf::Model& m, const std::string& name, int width, int height, const std::uint8_t* rgba) {
    std::vector<unsigned char> png;
    auto sink = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
    };
    if (!stbi_write_png_to_func(sink, &png, width, height, 4, rgba, width * 4))
        fail("export: cannot encode the {}x{} image {} as PNG", width, height, name);
    tinygltf::Image img;
    img.name = name;
    img.mimeType = "image/png";
    img.bufferView = add_view(m, png.data(), png.size());
    m.images.push_back(img);
    return static_cast<int>(m.images.size()) - 1;
}

int add_texture(tinygltf::Model& m, int image) {
    if (m.samplers.empty()) {
        tinygltf::Sampler s;
        s.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
        s.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
        m.samplers.push_back(s);
    }
    tinygltf::Texture tex;
    tex.source = image;
    tex.sampler = 0;
    m.textures.push_back(tex);
    return static_cast<int>(m.textures.size()) - 1;
}

}  // namespace emoface::apps::gltf
