// Accessor reading for the glTF loader (glTF 2.0 §3.6.2): every byte range is checked
// against its buffer view and buffer before it is read; strides, normalized integers
// (§3.11) and sparse substitution (§3.6.2.3) are handled here once for all attributes.

#include <algorithm>
#include <cmath>
#include <cstring>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {
namespace {

std::size_t component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return 0;
  }
}

/// One component as a double; normalized integers mapped to [0, 1] / [-1, 1] (§3.11).
double read_component(const std::uint8_t* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      std::int8_t v;
      std::memcpy(&v, p, 1);
      return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      std::uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return static_cast<double>(v);
    }
    default:
      return 0.0;
  }
}

struct ByteRange {
  const std::uint8_t* data = nullptr;
  std::size_t stride = 0;
};

/// Locates `count` elements of `element_size` bytes at `byte_offset` in buffer view `view`,
/// checking the whole range against the view and the view against its buffer (§3.6.2.4).
Result<ByteRange> locate(const Context& ctx, const ParsedFile& file, int view, std::size_t byte_offset,
                         std::size_t count, std::size_t element_size, std::size_t alignment, bool allow_stride,
                         const std::string& where) {
  const tinygltf::Model& model = file.model;
  if (view < 0 || static_cast<std::size_t>(view) >= model.bufferViews.size()) {
    return ctx.error(where, "bufferView " + std::to_string(view) + " is out of range");
  }
  const tinygltf::BufferView& bv = model.bufferViews[static_cast<std::size_t>(view)];
  if (bv.buffer < 0 || static_cast<std::size_t>(bv.buffer) >= model.buffers.size()) {
    return ctx.error(where, "bufferView " + std::to_string(view) + " refers to a missing buffer");
  }
  const std::size_t buffer_index = static_cast<std::size_t>(bv.buffer);
  if (buffer_index < file.buffer_problems.size() && !file.buffer_problems[buffer_index].empty()) {
    return ctx.error(where, "reads buffer " + std::to_string(bv.buffer) +
                                ", which has no data: " + file.buffer_problems[buffer_index]);
  }
  const std::vector<unsigned char>& buffer = model.buffers[buffer_index].data;
  if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset) {
    return ctx.error(where, "bufferView " + std::to_string(view) + " is out of range of buffer " +
                                std::to_string(bv.buffer) + " (" + std::to_string(buffer.size()) + " bytes)");
  }
  std::size_t stride = element_size;
  if (allow_stride && bv.byteStride != 0) {
    if (bv.byteStride < element_size) {
      return ctx.error(where, "byteStride " + std::to_string(bv.byteStride) + " is smaller than the element size " +
                                  std::to_string(element_size));
    }
    stride = bv.byteStride;
  }
  // §3.6.2.4: the accessor offset and the stride are multiples of the component size.
  if (byte_offset % alignment != 0 || (bv.byteOffset + byte_offset) % alignment != 0 || stride % alignment != 0) {
    return ctx.error(where, "data is not aligned to its component size (" + std::to_string(alignment) + " bytes)");
  }
  if (count > 0) {
    const std::size_t last = byte_offset + stride * (count - 1) + element_size;
    const bool overflow = stride != 0 && count - 1 > (SIZE_MAX - byte_offset - element_size) / stride;
    if (overflow || byte_offset > bv.byteLength || last > bv.byteLength) {
      return ctx.error(where, std::to_string(count) + " elements of " + std::to_string(element_size) +
                                  " bytes at offset " + std::to_string(byte_offset) +
                                  " are out of range of bufferView " + std::to_string(view) + " (" +
                                  std::to_string(bv.byteLength) + " bytes)");
    }
  }
  return ByteRange{buffer.data() + bv.byteOffset + byte_offset, stride};
}

}  // namespace

int component_count(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    case TINYGLTF_TYPE_MAT2:
      return 4;
    case TINYGLTF_TYPE_MAT3:
      return 9;
    case TINYGLTF_TYPE_MAT4:
      return 16;
    default:
      return 0;
  }
}

// Long because it is the accessor's checks and reads in the spec's order (type, count, budgets,
// dense data, sparse overrides, finiteness), each returning its own error at the same `where`.
Result<std::vector<double>> read_accessor(const Context& ctx, const ParsedFile& file, int index,
                                          std::size_t max_count) {
  const tinygltf::Model& model = file.model;
  const std::string where = "accessor " + std::to_string(index);
  if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) {
    return ctx.error(where, "is out of range (" + std::to_string(model.accessors.size()) + " accessors)");
  }
  const std::size_t ai = static_cast<std::size_t>(index);
  if (ai < file.accessor_problems.size() && !file.accessor_problems[ai].empty()) {
    return ctx.error(where, file.accessor_problems[ai]);
  }
  const tinygltf::Accessor& acc = model.accessors[ai];
  const std::size_t csize = component_size(acc.componentType);
  const int ncomp = component_count(acc.type);
  if (csize == 0) return ctx.error(where, "invalid componentType " + std::to_string(acc.componentType));
  if (ncomp == 0) return ctx.error(where, "invalid type " + std::to_string(acc.type));
  if (acc.type >= TINYGLTF_TYPE_MAT2 && acc.type <= TINYGLTF_TYPE_MAT4) {
    return ctx.error(where, "matrix accessors are not used by meshes");
  }
  if (acc.count < 1) return ctx.error(where, "count must be >= 1");
  if (acc.count > max_count) {
    return ctx.error(where,
                     "count " + std::to_string(acc.count) + " exceeds the limit of " + std::to_string(max_count));
  }
  const std::size_t n = static_cast<std::size_t>(ncomp);
  const std::size_t element_size = csize * n;
  // Budgets across the whole file: a thousand primitives each under the per-primitive limit
  // must not add up to an exhausted machine, least of all with zeros no byte of the file backs.
  const GltfLoadLimits& limits = ctx.options.limits;
  ctx.elements_read += acc.count;
  if (ctx.elements_read > limits.max_scene_elements)
    return ctx.error(where, "the file's accessors exceed the budget of " + std::to_string(limits.max_scene_elements) +
                                " elements in all");
  if (acc.bufferView < 0) {
    ctx.unbacked_elements_read += acc.count;
    if (ctx.unbacked_elements_read > limits.max_unbacked_elements)
      return ctx.error(where, "accessors without a bufferView (zeros) exceed the budget of " +
                                  std::to_string(limits.max_unbacked_elements) + " elements in all");
  }
  std::vector<double> values;
  if (acc.bufferView >= 0) {
    // Located before allocating, so the count is bounded by real data.
    auto range = locate(ctx, file, acc.bufferView, acc.byteOffset, acc.count, element_size, csize, true, where);
    if (!range) return range.error();
    values.resize(acc.count * n);
    for (std::size_t i = 0; i < acc.count; ++i) {
      const std::uint8_t* e = range->data + i * range->stride;
      for (std::size_t c = 0; c < n; ++c)
        values[i * n + c] = read_component(e + c * csize, acc.componentType, acc.normalized);
    }
  } else {
    values.assign(acc.count * n, 0.0);  // §3.6.2.3: no bufferView means zeros
  }
  if (acc.sparse.isSparse) {
    const auto& sp = acc.sparse;
    const std::string swhere = where + " sparse";
    if (sp.count < 1 || static_cast<std::size_t>(sp.count) > acc.count) {
      return ctx.error(swhere, "count " + std::to_string(sp.count) + " must be in [1, accessor count]");
    }
    const std::size_t scount = static_cast<std::size_t>(sp.count);
    const int icomp = sp.indices.componentType;
    const std::size_t isize = component_size(icomp);
    if (icomp != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && icomp != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        icomp != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
      return ctx.error(swhere, "indices componentType must be an unsigned integer type");
    }
    if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0) return ctx.error(swhere, "negative byteOffset");
    auto irange = locate(ctx, file, sp.indices.bufferView, static_cast<std::size_t>(sp.indices.byteOffset), scount,
                         isize, isize, false, swhere + " indices");
    if (!irange) return irange.error();
    auto vrange = locate(ctx, file, sp.values.bufferView, static_cast<std::size_t>(sp.values.byteOffset), scount,
                         element_size, csize, false, swhere + " values");
    if (!vrange) return vrange.error();
    double previous = -1.0;
    for (std::size_t k = 0; k < scount; ++k) {
      const double target = read_component(irange->data + k * isize, icomp, false);
      // §3.6.2.3: indices strictly increase and stay below the accessor's count.
      if (target <= previous || target >= static_cast<double>(acc.count)) {
        return ctx.error(swhere, "index " + std::to_string(static_cast<std::uint64_t>(target)) +
                                     " is out of range or not increasing");
      }
      previous = target;
      const std::size_t t = static_cast<std::size_t>(target);
      for (std::size_t c = 0; c < n; ++c) {
        values[t * n + c] =
            read_component(vrange->data + k * element_size + c * csize, acc.componentType, acc.normalized);
      }
    }
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      return ctx.error(where, "element " + std::to_string(i / n) + " is not finite (NaN or Inf)");
    }
  }
  return values;
}

}  // namespace engine::gltf_load
