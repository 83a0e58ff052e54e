// Reading glTF accessors with every length checked (internal: includes tinygltf; not
// installed). For the hand mesh's loader and the motion reader.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "nphand/util/check.h"

namespace nphand {

// Copies accessor `index` as `count` x `components` values of type T, honouring strides.
template <typename T>
std::vector<T> ReadAccessor(const tinygltf::Model& gltf, int index, int component_type, int components,
                            const std::string& source, const char* what) {
  NPHAND_THROW_CHECK(index >= 0 && index < static_cast<int>(gltf.accessors.size()), source, ": ", what,
                     " accessor missing");
  const tinygltf::Accessor& accessor = gltf.accessors[index];
  NPHAND_THROW_CHECK(accessor.componentType == component_type, source, ": ", what,
                     " has an unsupported component type ", accessor.componentType);
  NPHAND_THROW_CHECK(tinygltf::GetNumComponentsInType(accessor.type) == components, source, ": ", what,
                     " has ", tinygltf::GetNumComponentsInType(accessor.type), " components, expected ",
                     components);
  NPHAND_THROW_CHECK(accessor.bufferView >= 0 && accessor.bufferView < static_cast<int>(gltf.bufferViews.size()),
                     source, ": ", what, " has no buffer view");
  const tinygltf::BufferView& view = gltf.bufferViews[accessor.bufferView];
  NPHAND_THROW_CHECK(view.buffer >= 0 && view.buffer < static_cast<int>(gltf.buffers.size()), source, ": ",
                     what, " has no buffer");
  const std::vector<unsigned char>& buffer = gltf.buffers[view.buffer].data;
  const size_t element = sizeof(T) * components;
  const size_t stride = view.byteStride != 0 ? view.byteStride : element;
  const size_t begin = view.byteOffset + accessor.byteOffset;
  const size_t count = accessor.count;
  NPHAND_THROW_CHECK(count == 0 || begin + (count - 1) * stride + element <= buffer.size(), source, ": ",
                     what, " runs past the end of its buffer");
  std::vector<T> values(count * components);
  for (size_t i = 0; i < count; ++i) {
    std::memcpy(&values[i * components], buffer.data() + begin + i * stride, element);
  }
  return values;
}

}  // namespace nphand
