// glTF 2.0, .gltf and .glb (readGltf).
#include "RadiositySceneFormats.h"

#include "CheckedArithmetic.h"
#include "SceneText.h"
#include "SceneTextures.h"

#include "vtkCellArray.h"
#include "vtkPoints.h"

#include "vtk_nlohmannjson.h"
#include VTK_NLOHMANN_JSON(json.hpp)

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

namespace mlr::scenefile
{

namespace
{
using Json = nlohmann::json;

/// A glTF's external buffer or image file larger than this is refused before it is read:
/// every byte is held in memory.
constexpr std::uintmax_t MaxResourceFileBytes = std::uintmax_t(4) << 30;
// Real glTF files nest about 10 levels; extensions add a few more.
constexpr std::size_t MaxJsonDepth = 256;

/// The deepest nesting of arrays and objects in JSON text, skipping strings.
std::size_t jsonDepth(const std::string& text)
{
  std::size_t depth = 0, deepest = 0;
  bool inString = false;
  for (std::size_t i = 0; i < text.size(); ++i)
  {
    const char c = text[i];
    if (inString)
    {
      if (c == '\\')
      {
        ++i;
      }
      else if (c == '"')
      {
        inString = false;
      }
    }
    else if (c == '"')
    {
      inString = true;
    }
    else if (c == '[' || c == '{')
    {
      deepest = std::max(deepest, ++depth);
    }
    else if ((c == ']' || c == '}') && depth > 0)
    {
      --depth;
    }
  }
  return deepest;
}

std::int64_t componentBytes(std::int64_t componentType)
{
  switch (componentType)
  {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    case 5125:
    case 5126:
      return 4;
    default:
      return 0;
  }
}

std::int64_t typeComponents(const std::string& type)
{
  static const std::map<std::string, std::int64_t> components = { { "SCALAR", 1 }, { "VEC2", 2 },
    { "VEC3", 3 }, { "VEC4", 4 }, { "MAT2", 4 }, { "MAT3", 9 }, { "MAT4", 16 } };
  const auto found = components.find(type);
  return found == components.end() ? 0 : found->second;
}

/// Checks of the JSON that keep the reading below inside its arrays and buffers: every index
/// names an entry the file has, every accessor fits in its buffer view and buffer, the node
/// hierarchy is a forest.
class GltfChecks
{
public:
  GltfChecks(const Json& root, const std::string& path)
    : Root(root)
    , Path(path)
  {
  }

  [[noreturn]] void fail(const std::string& problem) const
  {
    throw FileError("the glTF file " + named(this->Path) + ": " + problem);
  }

  const Json& array(const char* name) const
  {
    static const Json empty = Json::array();
    const auto found = this->Root.find(name);
    if (found == this->Root.end())
    {
      return empty;
    }
    if (!found->is_array())
    {
      this->fail(std::string("'") + name + "' is not an array");
    }
    return *found;
  }

  /// "where.key", or "key" for a member of the document itself (`where` empty).
  static std::string member(const std::string& where, const char* key)
  {
    return where.empty() ? std::string(key) : where + "." + key;
  }

  /// An optional integer member; `fallback` when absent.
  std::int64_t integer(
    const Json& object, const char* key, const std::string& where, std::int64_t fallback = -1) const
  {
    const auto found = object.find(key);
    if (found == object.end())
    {
      return fallback;
    }
    if (!found->is_number_integer())
    {
      this->fail(member(where, key) + " is not a whole number");
    }
    return found->get<std::int64_t>();
  }

  /// An optional index into the top-level array `into`; -1 when absent.
  std::int64_t index(
    const Json& object, const char* key, const char* into, const std::string& where) const
  {
    const std::int64_t value = this->integer(object, key, where);
    if (object.contains(key) &&
      (value < 0 || value >= static_cast<std::int64_t>(this->array(into).size())))
    {
      this->fail(member(where, key) + " = " + std::to_string(value) + " but the file has " +
        std::to_string(this->array(into).size()) + " " + into);
    }
    return value;
  }

  /// A sparse accessor part: `count` (1 to the accessor's `elements`) indices of unsigned
  /// integers and as many values of `elementBytes`, each tightly packed in its bufferView.
  void checkSparse(
    const Json& sparse, const std::string& where, std::int64_t elements, std::int64_t elementBytes)
  {
    if (!sparse.is_object())
    {
      this->fail(where + " is not an object");
    }
    const std::int64_t count = this->integer(sparse, "count", where, 0);
    if (count < 1 || count > elements)
    {
      this->fail(where + ".count is " + std::to_string(count) +
        ": give 1 to the accessor's count (" + std::to_string(elements) + ")");
    }
    auto part = [&](const char* key, std::int64_t bytes)
    {
      const std::string at = where + "." + key;
      const auto found = sparse.find(key);
      if (found == sparse.end() || !found->is_object() || !found->contains("bufferView"))
      {
        this->fail(at + " has no bufferView");
      }
      const Json& view = this->array("bufferViews")[static_cast<std::size_t>(
        this->index(*found, "bufferView", "bufferViews", at))];
      const std::int64_t offset = this->integer(*found, "byteOffset", at, 0);
      const std::int64_t available = view["byteLength"].get<std::int64_t>();
      if (offset < 0 || !spanFits(offset, count, bytes, bytes, available))
      {
        this->fail(at + " (" + std::to_string(count) + " elements of " + std::to_string(bytes) +
          " bytes from byte " + std::to_string(offset) + ") does not fit in its bufferView (" +
          std::to_string(available) + " bytes)");
      }
    };
    const auto indices = sparse.find("indices");
    const std::int64_t type = indices != sparse.end() && indices->is_object()
      ? this->integer(*indices, "componentType", where, 0)
      : 0;
    if (type != 5121 && type != 5123 && type != 5125)
    {
      this->fail(where +
        ".indices.componentType is not an unsigned byte, short or int (5121, "
        "5123, 5125)");
    }
    part("indices", componentBytes(type));
    part("values", elementBytes);
  }

  const Json& object(const Json& parent, std::size_t i, const std::string& where) const
  {
    if (!parent[i].is_object())
    {
      this->fail(where + " is not an object");
    }
    return parent[i];
  }

  void run(bool glb, std::int64_t binBytes)
  {
    const auto asset = this->Root.find("asset");
    const std::string version = asset != this->Root.end() && asset->is_object() &&
        asset->contains("version") && (*asset)["version"].is_string()
      ? (*asset)["version"].get<std::string>()
      : std::string();
    if (version.rfind("2.", 0) != 0)
    {
      this->fail(version.empty() ? "it has no asset.version: it is not a glTF 2.0 file"
                                 : "it is glTF version " + printable(version) + ", not 2.x");
    }
    // Extensions a reader must understand: those of materials only change what is not read
    // here (or the emission strength, which is read), punctual lights are left out with a
    // warning, and a texture whose image is in a format of an extension (WebP, KTX2, AVIF) is
    // a texture that cannot be decoded: a warning, its factor alone is used. Geometry
    // compression is not supported.
    static const std::set<std::string> readable = { "KHR_texture_transform", "KHR_lights_punctual",
      "EXT_texture_webp", "KHR_texture_basisu", "EXT_texture_avif", "KHR_mesh_quantization",
      "EXT_mesh_gpu_instancing" };
    for (const auto& required : this->array("extensionsRequired"))
    {
      const std::string name =
        required.is_string() ? required.get<std::string>() : std::string("?");
      if (name.rfind("KHR_materials_", 0) != 0 && readable.count(name) == 0)
      {
        this->fail(
          "it requires the extension " + printable(name) + ", which this reader does not support");
      }
    }
    bool quantized = false;
    for (const char* list : { "extensionsUsed", "extensionsRequired" })
    {
      for (const auto& name : this->array(list))
      {
        quantized = quantized || (name.is_string() && name == "KHR_mesh_quantization");
      }
    }
    // Buffers and their views.
    const Json& buffers = this->array("buffers");
    for (std::size_t i = 0; i < buffers.size(); ++i)
    {
      const std::string where = "buffers[" + std::to_string(i) + "]";
      const Json& buffer = this->object(buffers, i, where);
      const std::int64_t length = this->integer(buffer, "byteLength", where);
      if (length < 0 || length > INT32_MAX)
      {
        this->fail(where + ".byteLength is missing or out of range");
      }
      this->BufferBytes.push_back(length);
      const auto uri = buffer.find("uri");
      if (uri == buffer.end())
      {
        if (!glb || i != 0)
        {
          this->fail(where + " has no uri (only the first buffer of a .glb file may lack one)");
        }
        if (binBytes < length)
        {
          this->fail(where + ".byteLength is " + std::to_string(length) +
            " but the BIN chunk holds " + std::to_string(std::max<std::int64_t>(0, binBytes)) +
            " bytes");
        }
      }
      else if (!uri->is_string())
      {
        this->fail(where + ".uri is not a string");
      }
    }
    const Json& views = this->array("bufferViews");
    for (std::size_t i = 0; i < views.size(); ++i)
    {
      const std::string where = "bufferViews[" + std::to_string(i) + "]";
      const Json& view = this->object(views, i, where);
      if (!view.contains("buffer"))
      {
        this->fail(where + " has no buffer");
      }
      const std::int64_t buffer = this->index(view, "buffer", "buffers", where);
      const std::int64_t offset = this->integer(view, "byteOffset", where, 0);
      const std::int64_t length = this->integer(view, "byteLength", where);
      const std::int64_t stride = this->integer(view, "byteStride", where, 0);
      const std::int64_t bufferBytes = this->BufferBytes[static_cast<std::size_t>(buffer)];
      if (!spanFits(offset, 1, 0, length, bufferBytes))
      {
        this->fail(where + " (" + std::to_string(length) + " bytes from byte " +
          std::to_string(offset) + ") does not fit in buffer " + std::to_string(buffer) + " (" +
          std::to_string(bufferBytes) + " bytes)");
      }
      if (view.contains("byteStride") && (stride < 4 || stride > 252))
      {
        this->fail(where + ".byteStride must be from 4 to 252");
      }
    }
    // Accessors, against their views.
    const Json& accessors = this->array("accessors");
    for (std::size_t i = 0; i < accessors.size(); ++i)
    {
      const std::string where = "accessors[" + std::to_string(i) + "]";
      const Json& accessor = this->object(accessors, i, where);
      const std::int64_t bytes = componentBytes(this->integer(accessor, "componentType", where, 0));
      const auto type = accessor.find("type");
      const std::int64_t components =
        type != accessor.end() && type->is_string() ? typeComponents(*type) : 0;
      const std::int64_t count = this->integer(accessor, "count", where, 0);
      const std::int64_t offset = this->integer(accessor, "byteOffset", where, 0);
      if (bytes == 0 || components == 0 || count < 1 || offset < 0)
      {
        this->fail(where + " has a missing or invalid componentType, type, count or byteOffset");
      }
      const std::int64_t element = bytes * components;
      if (count > INT32_MAX / element)
      {
        this->fail(where + " has " + std::to_string(count) + " elements: too many");
      }
      // Without a bufferView the accessor is zeros (which a sparse part may replace).
      if (accessor.contains("bufferView"))
      {
        const Json& view = views[static_cast<std::size_t>(
          this->index(accessor, "bufferView", "bufferViews", where))];
        const std::int64_t stride = std::max(this->integer(view, "byteStride", where, 0), element);
        const std::int64_t available = view["byteLength"].get<std::int64_t>();
        if (count > INT32_MAX / stride || !spanFits(offset, count, stride, element, available))
        {
          this->fail(where + " (" + std::to_string(count) + " elements of " +
            std::to_string(element) + " bytes from byte " + std::to_string(offset) +
            ") does not fit in its bufferView (" + std::to_string(available) + " bytes)");
        }
      }
      if (accessor.contains("sparse"))
      {
        this->checkSparse(accessor["sparse"], where + ".sparse", count, element);
      }
      this->AccessorType.push_back(*type);
      this->AccessorComponent.push_back(this->integer(accessor, "componentType", where, 0));
    }
    // Meshes.
    const Json& meshes = this->array("meshes");
    for (std::size_t m = 0; m < meshes.size(); ++m)
    {
      const std::string mesh = "meshes[" + std::to_string(m) + "]";
      const auto primitives = this->object(meshes, m, mesh).find("primitives");
      if (primitives == meshes[m].end() || !primitives->is_array())
      {
        this->fail(mesh + " has no primitives array");
      }
      for (std::size_t p = 0; p < primitives->size(); ++p)
      {
        const std::string where = mesh + ".primitives[" + std::to_string(p) + "]";
        const Json& primitive = this->object(*primitives, p, where);
        const auto attributes = primitive.find("attributes");
        if (attributes == primitive.end() || !attributes->is_object() ||
          !attributes->contains("POSITION"))
        {
          this->fail(where + " has no POSITION attribute");
        }
        for (const auto& attribute : attributes->items())
        {
          const std::int64_t a =
            this->index(*attributes, attribute.key().c_str(), "accessors", where + ".attributes");
          // KHR_mesh_quantization (gltfpack's output) stores positions as 8- or 16-bit
          // integers, normalized or not, which the node transforms scale back.
          const std::int64_t component = this->AccessorComponent[static_cast<std::size_t>(a)];
          if (attribute.key() == "POSITION" &&
            (this->AccessorType[static_cast<std::size_t>(a)] != "VEC3" ||
              (component != 5126 && (!quantized || component == 5125))))
          {
            this->fail(where + ".attributes.POSITION is not a VEC3 of floats" +
              (quantized ? std::string(" or of 8- or 16-bit integers (KHR_mesh_quantization)")
                         : std::string(" (integers need the extension KHR_mesh_quantization)")));
          }
        }
        const std::int64_t indices = this->index(primitive, "indices", "accessors", where);
        if (indices >= 0 &&
          (this->AccessorType[static_cast<std::size_t>(indices)] != "SCALAR" ||
            (this->AccessorComponent[static_cast<std::size_t>(indices)] != 5121 &&
              this->AccessorComponent[static_cast<std::size_t>(indices)] != 5123 &&
              this->AccessorComponent[static_cast<std::size_t>(indices)] != 5125)))
        {
          this->fail(where + ".indices is not a SCALAR of unsigned integers");
        }
        this->index(primitive, "material", "materials", where);
        const std::int64_t mode = this->integer(primitive, "mode", where, 4);
        if (mode < 0 || mode > 6)
        {
          this->fail(
            where + ".mode = " + std::to_string(mode) + " is not a glTF primitive mode (0 to 6)");
        }
        const auto targets = primitive.find("targets");
        if (targets != primitive.end())
        {
          if (!targets->is_array())
          {
            this->fail(where + ".targets is not an array");
          }
          for (const auto& target : *targets)
          {
            if (!target.is_object())
            {
              this->fail(where + ".targets holds a non-object");
            }
            for (const auto& attribute : target.items())
            {
              this->index(target, attribute.key().c_str(), "accessors", where + ".targets");
            }
          }
        }
      }
    }
    // Materials' textures, textures' images and samplers, images' views.
    const Json& materials = this->array("materials");
    for (std::size_t i = 0; i < materials.size(); ++i)
    {
      const std::string where = "materials[" + std::to_string(i) + "]";
      const Json& material = this->object(materials, i, where);
      auto textureOf = [&](const Json& holder, const char* key, const std::string& at)
      {
        const auto info = holder.find(key);
        if (info != holder.end())
        {
          if (!info->is_object() || !info->contains("index"))
          {
            this->fail(at + "." + key + " has no texture index");
          }
          this->index(*info, "index", "textures", at + "." + key);
        }
      };
      for (const char* key : { "normalTexture", "occlusionTexture", "emissiveTexture" })
      {
        textureOf(material, key, where);
      }
      const auto pbr = material.find("pbrMetallicRoughness");
      if (pbr != material.end() && pbr->is_object())
      {
        textureOf(*pbr, "baseColorTexture", where + ".pbrMetallicRoughness");
        textureOf(*pbr, "metallicRoughnessTexture", where + ".pbrMetallicRoughness");
      }
      const auto extensions = material.find("extensions");
      if (extensions != material.end() && extensions->is_object() &&
        extensions->contains("KHR_materials_pbrSpecularGlossiness") &&
        (*extensions)["KHR_materials_pbrSpecularGlossiness"].is_object())
      {
        textureOf((*extensions)["KHR_materials_pbrSpecularGlossiness"], "diffuseTexture",
          where + ".extensions.KHR_materials_pbrSpecularGlossiness");
      }
    }
    const Json& textures = this->array("textures");
    for (std::size_t i = 0; i < textures.size(); ++i)
    {
      const std::string where = "textures[" + std::to_string(i) + "]";
      this->index(this->object(textures, i, where), "source", "images", where);
      this->index(textures[i], "sampler", "samplers", where);
      // EXT_texture_webp, KHR_texture_basisu, EXT_texture_avif: an image of their format.
      const auto extensions = textures[i].find("extensions");
      if (extensions != textures[i].end() && extensions->is_object())
      {
        for (const auto& extension : extensions->items())
        {
          if (extension.value().is_object())
          {
            this->index(extension.value(), "source", "images",
              where + ".extensions." + printable(extension.key()));
          }
        }
      }
    }
    const Json& images = this->array("images");
    for (std::size_t i = 0; i < images.size(); ++i)
    {
      const std::string where = "images[" + std::to_string(i) + "]";
      const Json& image = this->object(images, i, where);
      // An image in a bufferView of another format than PNG or JPEG (image/webp, image/ktx2)
      // is decoded when a material uses it, and is a warning then, as an image file is.
      if (this->index(image, "bufferView", "bufferViews", where) >= 0)
      {
        continue;
      }
      if (!image.contains("uri") || !image["uri"].is_string())
      {
        this->fail(where + " has neither a uri nor a bufferView");
      }
    }
    // Nodes: indices in range, each node with at most one parent, no cycles.
    const Json& nodes = this->array("nodes");
    std::vector<std::int64_t> parent(nodes.size(), -1);
    for (std::size_t i = 0; i < nodes.size(); ++i)
    {
      const std::string where = "nodes[" + std::to_string(i) + "]";
      const Json& node = this->object(nodes, i, where);
      this->index(node, "mesh", "meshes", where);
      this->index(node, "skin", "skins", where);
      this->index(node, "camera", "cameras", where);
      const auto children = node.find("children");
      if (children == node.end())
      {
        continue;
      }
      if (!children->is_array())
      {
        this->fail(where + ".children is not an array");
      }
      for (const auto& child : *children)
      {
        if (!child.is_number_integer() || child.get<std::int64_t>() < 0 ||
          child.get<std::int64_t>() >= static_cast<std::int64_t>(nodes.size()))
        {
          this->fail(where + ".children names a node the file does not have");
        }
        auto& childParent = parent[child.get<std::size_t>()];
        if (childParent >= 0 || child.get<std::size_t>() == i)
        {
          this->fail("node " + std::to_string(child.get<std::int64_t>()) +
            " has two parents or is its own child");
        }
        childParent = static_cast<std::int64_t>(i);
      }
    }
    // Each node has at most one parent, so a cycle is a chain up that meets itself. Marking
    // the nodes whose chain is known to end keeps the walk linear: a chain of 10^5 nodes
    // would otherwise be climbed once from each of them.
    enum : char
    {
      Unseen,
      OnChain,
      Ends
    };
    std::vector<char> state(nodes.size(), Unseen);
    std::vector<std::size_t> chain;
    for (std::size_t i = 0; i < nodes.size(); ++i)
    {
      chain.clear();
      std::int64_t up = static_cast<std::int64_t>(i);
      while (up >= 0 && state[static_cast<std::size_t>(up)] != Ends)
      {
        if (state[static_cast<std::size_t>(up)] == OnChain)
        {
          this->fail("the node hierarchy has a cycle through node " + std::to_string(up));
        }
        state[static_cast<std::size_t>(up)] = OnChain;
        chain.push_back(static_cast<std::size_t>(up));
        up = parent[static_cast<std::size_t>(up)];
      }
      for (const std::size_t node : chain)
      {
        state[node] = Ends;
      }
    }
    this->Parents = parent;
    const Json& scenes = this->array("scenes");
    for (std::size_t i = 0; i < scenes.size(); ++i)
    {
      const std::string where = "scenes[" + std::to_string(i) + "]";
      const auto list = this->object(scenes, i, where).find("nodes");
      if (list == scenes[i].end())
      {
        continue;
      }
      if (!list->is_array())
      {
        this->fail(where + ".nodes is not an array");
      }
      for (const auto& node : *list)
      {
        if (!node.is_number_integer() || node.get<std::int64_t>() < 0 ||
          node.get<std::int64_t>() >= static_cast<std::int64_t>(nodes.size()))
        {
          this->fail(where + ".nodes names a node the file does not have");
        }
      }
    }
    this->index(this->Root, "scene", "scenes", "");
    // Skins and animations read accessors and nodes too.
    const Json& skins = this->array("skins");
    for (std::size_t i = 0; i < skins.size(); ++i)
    {
      const std::string where = "skins[" + std::to_string(i) + "]";
      const Json& skin = this->object(skins, i, where);
      this->index(skin, "inverseBindMatrices", "accessors", where);
      this->index(skin, "skeleton", "nodes", where);
      const auto joints = skin.find("joints");
      if (joints == skin.end() || !joints->is_array())
      {
        this->fail(where + " has no joints array");
      }
      for (const auto& joint : *joints)
      {
        if (!joint.is_number_integer() || joint.get<std::int64_t>() < 0 ||
          joint.get<std::int64_t>() >= static_cast<std::int64_t>(nodes.size()))
        {
          this->fail(where + ".joints names a node the file does not have");
        }
      }
    }
    const Json& animations = this->array("animations");
    for (std::size_t i = 0; i < animations.size(); ++i)
    {
      const std::string where = "animations[" + std::to_string(i) + "]";
      const Json& animation = this->object(animations, i, where);
      const auto samplers = animation.find("samplers");
      const auto channels = animation.find("channels");
      if (samplers == animation.end() || !samplers->is_array() || channels == animation.end() ||
        !channels->is_array())
      {
        this->fail(where + " has no samplers or channels array");
      }
      for (const auto& sampler : *samplers)
      {
        if (!sampler.is_object() || !sampler.contains("input") || !sampler.contains("output"))
        {
          this->fail(where + " has a sampler without input or output");
        }
        this->index(sampler, "input", "accessors", where + ".samplers");
        this->index(sampler, "output", "accessors", where + ".samplers");
      }
      for (const auto& channel : *channels)
      {
        const std::int64_t sampler =
          channel.is_object() ? this->integer(channel, "sampler", where, -1) : -1;
        if (sampler < 0 || sampler >= static_cast<std::int64_t>(samplers->size()))
        {
          this->fail(where + " has a channel without a valid sampler");
        }
        const auto target = channel.find("target");
        if (target == channel.end() || !target->is_object())
        {
          this->fail(where + " has a channel without a target");
        }
        this->index(*target, "node", "nodes", where + ".channels.target");
      }
    }
  }

  std::vector<std::int64_t> Parents;

private:
  const Json& Root;
  std::string Path;
  std::vector<std::int64_t> BufferBytes;
  std::vector<std::string> AccessorType;
  std::vector<std::int64_t> AccessorComponent;
};

std::uint32_t littleEndian32(const unsigned char* bytes)
{
  return static_cast<std::uint32_t>(bytes[0]) | (static_cast<std::uint32_t>(bytes[1]) << 8) |
    (static_cast<std::uint32_t>(bytes[2]) << 16) | (static_cast<std::uint32_t>(bytes[3]) << 24);
}

/// The JSON of a .gltf file, or of a .glb file's first chunk (and its BIN chunk in `bin`;
/// binBytes is its size, -1 without one).
Json readGltfJson(const std::string& path, bool glb, std::string& bin, std::int64_t& binBytes)
{
  std::ifstream in = openFile(path, "glTF file");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  binBytes = -1;
  auto fail = [&](const std::string& problem)
  { throw FileError("the glTF file " + named(path) + " " + problem); };
  if (glb)
  {
    const auto* bytes = reinterpret_cast<const unsigned char*>(text.data());
    if (text.size() < 20 || text.compare(0, 4, "glTF") != 0)
    {
      fail("is not a binary glTF (.glb) file: it does not start with 'glTF'");
    }
    if (littleEndian32(bytes + 4) != 2)
    {
      fail("is binary glTF version " + std::to_string(littleEndian32(bytes + 4)) + ", not 2");
    }
    if (littleEndian32(bytes + 8) != text.size())
    {
      fail("says it holds " + std::to_string(littleEndian32(bytes + 8)) + " bytes but has " +
        std::to_string(text.size()) + ": it is truncated or damaged");
    }
    const std::uint64_t jsonBytes = littleEndian32(bytes + 12);
    if (text.compare(16, 4, "JSON") != 0 || 20 + jsonBytes > text.size())
    {
      fail("has no complete JSON chunk first");
    }
    // The chunks must tile the file exactly, as vtkGLTFDocumentLoader assumes.
    std::uint64_t at = 20 + jsonBytes;
    while (at < text.size())
    {
      if (at + 8 > text.size())
      {
        fail("ends inside a chunk header: it is truncated or damaged");
      }
      const std::uint64_t chunk = littleEndian32(bytes + at);
      if (at + 8 + chunk > text.size())
      {
        fail("has a chunk longer than the file: it is truncated or damaged");
      }
      if (text.compare(at + 4, 4, std::string("BIN\0", 4)) == 0 && binBytes < 0)
      {
        binBytes = static_cast<std::int64_t>(chunk);
        bin = text.substr(at + 8, chunk);
      }
      at += 8 + chunk;
    }
    text = text.substr(20, jsonBytes);
  }
  // nlohmann's parser recurses once per nesting level, so a deep file overflows the stack
  // before any error could be raised: the depth is measured first, without recursion.
  if (const std::size_t depth = jsonDepth(text); depth > MaxJsonDepth)
  {
    fail("nests its JSON " + std::to_string(depth) + " levels deep, more than the " +
      std::to_string(MaxJsonDepth) + " this reader takes: the file is damaged or hostile");
  }
  try
  {
    Json root = Json::parse(text);
    if (!root.is_object())
    {
      fail("is not a glTF document: its JSON is not an object");
    }
    return root;
  }
  catch (const Json::exception& e)
  {
    fail(std::string("is not valid JSON: ") + e.what());
  }
  return {};
}

/// Decodes standard base64 (the payload of a data: URI); false on a character outside it.
bool decodeBase64(const std::string& text, std::string& bytes)
{
  bytes.clear();
  std::uint32_t chunk = 0;
  int bits = 0;
  for (char c : text)
  {
    int value = -1;
    if (c >= 'A' && c <= 'Z')
    {
      value = c - 'A';
    }
    else if (c >= 'a' && c <= 'z')
    {
      value = c - 'a' + 26;
    }
    else if (c >= '0' && c <= '9')
    {
      value = c - '0' + 52;
    }
    else if (c == '+' || c == '-')
    {
      value = 62;
    }
    else if (c == '/' || c == '_')
    {
      value = 63;
    }
    else if (c == '=' || std::isspace(static_cast<unsigned char>(c)))
    {
      continue;
    }
    if (value < 0)
    {
      return false;
    }
    chunk = (chunk << 6) | static_cast<std::uint32_t>(value);
    bits += 6;
    if (bits >= 8)
    {
      bits -= 8;
      bytes += static_cast<char>((chunk >> bits) & 0xff);
    }
  }
  return true;
}

/// A relative URI of a glTF resource as a path: %XX escapes decoded.
std::string uriPath(const std::string& uri)
{
  std::string path;
  for (std::size_t i = 0; i < uri.size(); ++i)
  {
    if (uri[i] == '%' && i + 2 < uri.size() &&
      std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
      std::isxdigit(static_cast<unsigned char>(uri[i + 2])))
    {
      path += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
      i += 2;
    }
    else
    {
      path += uri[i];
    }
  }
  return path;
}

/// One component of an accessor; a normalized integer maps to [0, 1] (unsigned) or [-1, 1].
template <typename T>
double component(const char* at, bool normalized)
{
  T value;
  std::memcpy(&value, at, sizeof(T));
  if (!normalized)
  {
    return static_cast<double>(value);
  }
  return std::max(
    static_cast<double>(value) / static_cast<double>(std::numeric_limits<T>::max()), -1.0);
}

/// A glTF document whose indices and sizes GltfChecks has checked: buffers loaded, accessors
/// read as numbers.
class GltfDocument
{
public:
  GltfDocument(const Json& root, const std::string& path, std::string bin)
    : Root(root)
    , Path(path)
    , Folder(std::filesystem::path(path).parent_path())
  {
    const Json& buffers = root.contains("buffers") ? root["buffers"] : Json::array();
    // Buffers that name the same URI share one copy: a file that names itself thousands of
    // times would otherwise be read, and held, thousands of times.
    std::map<std::string, std::shared_ptr<const std::string>> byUri;
    for (std::size_t i = 0; i < buffers.size(); ++i)
    {
      const std::size_t length = buffers[i]["byteLength"].get<std::size_t>();
      std::shared_ptr<const std::string> bytes;
      if (!buffers[i].contains("uri"))
      {
        // GltfChecks: only buffer 0 of a .glb, and the BIN chunk holds byteLength
        bytes = std::make_shared<const std::string>(std::move(bin));
      }
      else
      {
        const std::string uri = buffers[i]["uri"].get<std::string>();
        auto& shared = byUri[uri];
        if (!shared)
        {
          shared = std::make_shared<const std::string>(
            this->resource(uri, "buffers[" + std::to_string(i) + "]"));
        }
        bytes = shared;
      }
      if (bytes->size() < length)
      {
        this->fail("buffers[" + std::to_string(i) + "] holds " + std::to_string(bytes->size()) +
          " bytes, less than its byteLength " + std::to_string(length));
      }
      this->Buffers.push_back(std::move(bytes));
    }
  }

  [[noreturn]] void fail(const std::string& problem) const
  {
    throw FileError("the glTF file " + named(this->Path) + ": " + problem);
  }

  /// The bytes of a data: URI or of a file beside the glTF file.
  std::string resource(const std::string& uri, const std::string& what) const
  {
    if (uri.rfind("data:", 0) == 0)
    {
      const auto comma = uri.find(',');
      std::string bytes;
      if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos ||
        !decodeBase64(uri.substr(comma + 1), bytes))
      {
        this->fail(what + " has a data: URI that is not base64");
      }
      return bytes;
    }
    const std::filesystem::path file = this->Folder / uriPath(uri);
    std::error_code error;
    if (!std::filesystem::is_regular_file(file, error))
    {
      this->fail(what + " names the file " + named(file.string()) + ", which does not exist");
    }
    const std::uintmax_t size = std::filesystem::file_size(file, error);
    if (error || size > MaxResourceFileBytes)
    {
      this->fail(what + ": the file " + named(file.string()) +
        (error ? " has a size that cannot be read" : " is over the 4 GiB this reader takes"));
    }
    std::ifstream in(file, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad())
    {
      this->fail(what + ": the file " + named(file.string()) + " could not be read");
    }
    return bytes;
  }

  /// The bytes of a buffer view (checked to fit in its buffer).
  std::string view(std::size_t index) const
  {
    const Json& view = this->Root["bufferViews"][index];
    return this->Buffers[view["buffer"].get<std::size_t>()]->substr(
      view.value("byteOffset", std::size_t(0)), view["byteLength"].get<std::size_t>());
  }

  /// Accessor `index` as numbers, `components` per element; normalized integers in [0, 1].
  /// Zeros where it has no bufferView, then its sparse values, if any, in their places.
  std::vector<double> accessor(std::size_t index, std::size_t& components) const
  {
    const Json& accessor = this->Root["accessors"][index];
    const std::int64_t type = accessor["componentType"].get<std::int64_t>();
    components = static_cast<std::size_t>(typeComponents(accessor["type"].get<std::string>()));
    const std::size_t count = accessor["count"].get<std::size_t>();
    const bool normalized = accessor.value("normalized", false);
    std::vector<double> values(count * components);
    if (accessor.contains("bufferView"))
    {
      this->read(accessor["bufferView"].get<std::size_t>(),
        accessor.value("byteOffset", std::size_t(0)), true, type, components, normalized, count,
        values.data());
    }
    if (accessor.contains("sparse"))
    {
      const Json& sparse = accessor["sparse"];
      const std::size_t changed = sparse["count"].get<std::size_t>();
      const Json& indices = sparse["indices"];
      const Json& given = sparse["values"];
      std::vector<double> where(changed), replacements(changed * components);
      this->read(indices["bufferView"].get<std::size_t>(),
        indices.value("byteOffset", std::size_t(0)), false,
        indices["componentType"].get<std::int64_t>(), 1, false, changed, where.data());
      this->read(given["bufferView"].get<std::size_t>(), given.value("byteOffset", std::size_t(0)),
        false, type, components, normalized, changed, replacements.data());
      for (std::size_t i = 0; i < changed; ++i)
      {
        if (!(where[i] < static_cast<double>(count)))
        {
          this->fail("accessors[" + std::to_string(index) + "].sparse names element " +
            std::to_string(static_cast<std::uint64_t>(where[i])) + " but the accessor has " +
            std::to_string(count));
        }
        std::copy_n(&replacements[i * components], components,
          &values[static_cast<std::size_t>(where[i]) * components]);
      }
    }
    return values;
  }

  /// `count` elements of `components` numbers of glTF component type `type` from bufferView
  /// `viewIndex` at `offset` (checked to fit), into `out`: spaced by the view's byteStride
  /// where `strided`, tightly packed otherwise (a sparse part's).
  void read(std::size_t viewIndex, std::size_t offset, bool strided, std::int64_t type,
    std::size_t components, bool normalized, std::size_t count, double* out) const
  {
    const Json& view = this->Root["bufferViews"][viewIndex];
    const std::size_t bytes = static_cast<std::size_t>(componentBytes(type));
    const std::size_t stride = std::max<std::size_t>(
      strided ? view.value("byteStride", std::size_t(0)) : 0, bytes * components);
    const std::string& buffer = *this->Buffers[view["buffer"].get<std::size_t>()];
    const std::size_t start = view.value("byteOffset", std::size_t(0)) + offset;
    for (std::size_t e = 0; e < count; ++e)
    {
      for (std::size_t c = 0; c < components; ++c)
      {
        const char* at = buffer.data() + start + e * stride + c * bytes;
        double value = 0;
        switch (type)
        {
          case 5120:
            value = component<std::int8_t>(at, normalized);
            break;
          case 5121:
            value = component<std::uint8_t>(at, normalized);
            break;
          case 5122:
            value = component<std::int16_t>(at, normalized);
            break;
          case 5123:
            value = component<std::uint16_t>(at, normalized);
            break;
          case 5125:
            value = component<std::uint32_t>(at, false);
            break;
          default:
            value = component<float>(at, false);
        }
        out[e * components + c] = value;
      }
    }
  }

  /// The mean linear colour of texture `texture` (sRGB-encoded, as base colour and emissive
  /// textures are); (1, 1, 1) with a warning when its image cannot be decoded.
  std::array<double, 3> textureMean(
    std::size_t texture, const std::string& what, const Warn& warn) const
  {
    const Json& entry = this->Root["textures"][texture];
    std::string problem;
    std::optional<std::array<double, 3>> mean;
    // The core source (PNG or JPEG, a fallback when an extension gives another format), else
    // the image of an extension such as EXT_texture_webp, which is warned of below.
    std::int64_t source = entry.contains("source") ? entry["source"].get<std::int64_t>() : -1;
    if (source < 0 && entry.contains("extensions") && entry["extensions"].is_object())
    {
      for (const auto& extension : entry["extensions"].items())
      {
        if (source < 0 && extension.value().is_object() && extension.value().contains("source"))
        {
          source = extension.value()["source"].get<std::int64_t>();
        }
      }
    }
    if (source < 0)
    {
      problem = "its texture has no image";
    }
    else
    {
      // Each image is decoded once, however many textures and materials name it.
      const std::size_t image = static_cast<std::size_t>(source);
      auto known = this->ImageMeans.find(image);
      if (known == this->ImageMeans.end())
      {
        const Json& source = this->Root["images"][image];
        std::string bytes;
        if (source.contains("bufferView"))
        {
          bytes = this->view(source["bufferView"].get<std::size_t>());
        }
        else
        {
          bytes = this->resource(source["uri"].get<std::string>(), what + "'s image");
        }
        std::string imageProblem;
        std::optional<std::array<double, 3>> imageMeanColour = imageMean(bytes, imageProblem);
        known =
          this->ImageMeans.emplace(image, std::make_pair(imageMeanColour, imageProblem)).first;
      }
      mean = known->second.first;
      problem = known->second.second;
    }
    if (!mean)
    {
      warn(what + ": " + problem + ", so its factor alone is used");
      return { { 1, 1, 1 } };
    }
    return *mean;
  }

  /// The local transform of node `index`: its matrix, or translation x rotation x scale.
  std::array<double, 16> localTransform(std::size_t index) const
  {
    const Json& node = this->Root["nodes"][index];
    const std::string where = "nodes[" + std::to_string(index) + "]";
    auto numbers = [&](const char* key, std::size_t size, std::vector<double> fallback)
    {
      const auto found = node.find(key);
      if (found == node.end())
      {
        return fallback;
      }
      if (!found->is_array() || found->size() != size)
      {
        this->fail(where + "." + key + " is not " + std::to_string(size) + " numbers");
      }
      std::vector<double> values;
      for (const auto& value : *found)
      {
        if (!value.is_number() || !std::isfinite(value.get<double>()))
        {
          this->fail(where + "." + key + " is not " + std::to_string(size) + " finite numbers");
        }
        values.push_back(value.get<double>());
      }
      return values;
    };
    std::array<double, 16> m{}; // row-major
    if (node.contains("matrix"))
    {
      const auto columnMajor = numbers("matrix", 16, {});
      for (std::size_t r = 0; r < 4; ++r)
      {
        for (std::size_t c = 0; c < 4; ++c)
        {
          m[4 * r + c] = columnMajor[4 * c + r];
        }
      }
      return m;
    }
    return this->trs(numbers("translation", 3, { 0, 0, 0 }).data(),
      numbers("rotation", 4, { 0, 0, 0, 1 }).data(), numbers("scale", 3, { 1, 1, 1 }).data(),
      where + ".rotation");
  }

  /// The row-major matrix of translation t x rotation q (a quaternion x, y, z, w) x scale s.
  std::array<double, 16> trs(
    const double* t, const double* q, const double* s, const std::string& rotation) const
  {
    std::array<double, 16> m{};
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(norm > 0) || !std::isfinite(norm))
    {
      this->fail(rotation + " is a zero (or not a finite) quaternion");
    }
    const double x = q[0] / norm, y = q[1] / norm, z = q[2] / norm, w = q[3] / norm;
    const double r[3][3] = { { 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w) },
      { 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w) },
      { 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y) } };
    for (std::size_t i = 0; i < 3; ++i)
    {
      for (std::size_t j = 0; j < 3; ++j)
      {
        m[4 * i + j] = r[i][j] * s[j];
      }
      m[4 * i + 3] = t[i];
    }
    m[15] = 1;
    return m;
  }

private:
  const Json& Root;
  std::string Path;
  std::filesystem::path Folder;
  std::vector<std::shared_ptr<const std::string>> Buffers;
  /// Decoded images' mean colours (or why there is none), by image index.
  mutable std::map<std::size_t, std::pair<std::optional<std::array<double, 3>>, std::string>>
    ImageMeans;
};

std::array<double, 16> multiply(const std::array<double, 16>& a, const std::array<double, 16>& b)
{
  std::array<double, 16> m{};
  for (std::size_t r = 0; r < 4; ++r)
  {
    for (std::size_t c = 0; c < 4; ++c)
    {
      for (std::size_t k = 0; k < 4; ++k)
      {
        m[4 * r + c] += a[4 * r + k] * b[4 * k + c];
      }
    }
  }
  return m;
}

/// A colour factor of a material: `size` numbers (glTF keeps them in [0, 1]; emission
/// strength scales emissiveFactor).
std::array<double, 3> colourFactor(const Json& holder, const char* key, std::size_t size,
  double fallback, const std::string& what, const std::function<void(const std::string&)>& fail)
{
  std::array<double, 3> rgb{ { fallback, fallback, fallback } };
  const auto found = holder.find(key);
  if (found == holder.end())
  {
    return rgb;
  }
  if (!found->is_array() || found->size() != size)
  {
    fail(what + "." + key + " is not " + std::to_string(size) + " numbers");
  }
  for (std::size_t c = 0; c < 3; ++c)
  {
    const Json& value = (*found)[c];
    if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0)
    {
      fail(what + "." + key + " must hold numbers, 0 or more");
    }
    rgb[c] = value.get<double>();
  }
  return rgb;
}
/// The EXT_mesh_gpu_instancing attributes of a node (TRANSLATION, ROTATION, SCALE: accessor
/// indices, -1 when absent) and its number of instances; 0 instances when it has none.
struct Instancing
{
  std::int64_t translation = -1, rotation = -1, scale = -1;
  std::uint64_t count = 0;
};

Instancing instancingOf(const GltfChecks& checks, const Json& node, const std::string& where)
{
  Instancing instancing;
  const auto extensions = node.find("extensions");
  if (extensions == node.end() || !extensions->is_object() ||
    !extensions->contains("EXT_mesh_gpu_instancing"))
  {
    return instancing;
  }
  const Json& extension = (*extensions)["EXT_mesh_gpu_instancing"];
  const std::string at = where + ".extensions.EXT_mesh_gpu_instancing";
  if (!extension.is_object() || !extension.contains("attributes") ||
    !extension["attributes"].is_object())
  {
    checks.fail(at + " has no attributes object");
  }
  const Json& attributes = extension["attributes"];
  const Json& accessors = checks.array("accessors");
  std::int64_t count = -1;
  for (const auto& [key, size, slot] : { std::make_tuple("TRANSLATION", 3, &instancing.translation),
         std::make_tuple("ROTATION", 4, &instancing.rotation),
         std::make_tuple("SCALE", 3, &instancing.scale) })
  {
    *slot = checks.index(attributes, key, "accessors", at + ".attributes");
    if (*slot < 0)
    {
      continue;
    }
    const Json& accessor = accessors[static_cast<std::size_t>(*slot)];
    const std::int64_t n = accessor["count"].get<std::int64_t>();
    if (typeComponents(accessor["type"].get<std::string>()) != size || (count >= 0 && n != count))
    {
      checks.fail(at + ".attributes." + key + " is not a VEC" + std::to_string(size) +
        " with one element per instance, as many as the other attributes");
    }
    count = n;
  }
  instancing.count = count > 0 ? static_cast<std::uint64_t>(count) : 1;
  return instancing;
}

/// The transforms of the instances of a node's mesh in the node's frame: one identity without
/// EXT_mesh_gpu_instancing, else each instance's translation x rotation x scale.
std::vector<std::array<double, 16>> instanceTransforms(
  const GltfDocument& document, const GltfChecks& checks, const Json& node, std::size_t index)
{
  const std::string where = "nodes[" + std::to_string(index) + "]";
  const Instancing instancing = instancingOf(checks, node, where);
  std::array<double, 16> identity{};
  identity[0] = identity[5] = identity[10] = identity[15] = 1;
  if (instancing.count == 0)
  {
    return { identity };
  }
  auto values = [&](std::int64_t accessor, std::size_t size, std::vector<double> fallback)
  {
    if (accessor < 0)
    {
      std::vector<double> repeated;
      for (std::uint64_t i = 0; i < instancing.count; ++i)
      {
        repeated.insert(repeated.end(), fallback.begin(), fallback.end());
      }
      return repeated;
    }
    std::size_t components = 0;
    std::vector<double> read = document.accessor(static_cast<std::size_t>(accessor), components);
    if (components != size || read.size() != size * instancing.count)
    {
      document.fail(where + ": its EXT_mesh_gpu_instancing attributes do not give every instance");
    }
    return read;
  };
  const auto t = values(instancing.translation, 3, { 0, 0, 0 });
  const auto q = values(instancing.rotation, 4, { 0, 0, 0, 1 });
  const auto s = values(instancing.scale, 3, { 1, 1, 1 });
  std::vector<std::array<double, 16>> transforms;
  transforms.reserve(static_cast<std::size_t>(instancing.count));
  for (std::size_t i = 0; i < instancing.count; ++i)
  {
    for (const double value :
      { t[3 * i], t[3 * i + 1], t[3 * i + 2], s[3 * i], s[3 * i + 1], s[3 * i + 2] })
    {
      if (!std::isfinite(value))
      {
        document.fail(where + ": instance " + std::to_string(i) +
          " of EXT_mesh_gpu_instancing has a translation or scale that is not finite");
      }
    }
    transforms.push_back(document.trs(&t[3 * i], &q[4 * i], &s[3 * i],
      where + ": the rotation of instance " + std::to_string(i) + " of EXT_mesh_gpu_instancing"));
  }
  return transforms;
}

/// The points and triangles the nodes under `roots` draw, counting each instance of a mesh:
/// a mesh named by 10^5 nodes is drawn 10^5 times, and that is known before drawing any.
std::pair<std::uint64_t, std::uint64_t> drawnSize(
  const GltfChecks& checks, const std::vector<std::int64_t>& roots)
{
  const Json& nodes = checks.array("nodes");
  const Json& meshes = checks.array("meshes");
  const Json& accessors = checks.array("accessors");
  auto count = [&](const Json& primitive, const char* attribute) -> std::uint64_t
  {
    const Json& index = attribute ? primitive["attributes"][attribute] : primitive["indices"];
    return accessors[index.get<std::size_t>()]["count"].get<std::uint64_t>();
  };
  std::vector<std::pair<std::uint64_t, std::uint64_t>> perMesh(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m)
  {
    for (const Json& primitive : meshes[m]["primitives"])
    {
      const std::int64_t mode = primitive.value("mode", std::int64_t(4));
      if (mode < 4 || !primitive.contains("attributes") ||
        !primitive["attributes"].contains("POSITION"))
      {
        continue;
      }
      const std::uint64_t points = count(primitive, "POSITION");
      const std::uint64_t corners =
        primitive.contains("indices") ? count(primitive, nullptr) : points;
      // A primitive keeps only the vertices its triangles use.
      perMesh[m].first = saturatingSum(perMesh[m].first, std::min(points, corners));
      perMesh[m].second = saturatingSum(perMesh[m].second, mode == 4 ? corners / 3 : corners);
    }
  }
  std::uint64_t points = 0, triangles = 0;
  std::vector<std::size_t> stack(roots.begin(), roots.end());
  while (!stack.empty())
  {
    const std::size_t index = stack.back();
    const Json& node = nodes[index];
    stack.pop_back();
    if (node.contains("mesh"))
    {
      const auto& [p, t] = perMesh[node["mesh"].get<std::size_t>()];
      const std::uint64_t instances = std::max<std::uint64_t>(
        1, instancingOf(checks, node, "nodes[" + std::to_string(index) + "]").count);
      points = saturatingSum(points, saturatingProduct(p, instances));
      triangles = saturatingSum(triangles, saturatingProduct(t, instances));
    }
    if (node.contains("children"))
    {
      for (const Json& child : node["children"])
      {
        stack.push_back(child.get<std::size_t>());
      }
    }
  }
  return { points, triangles };
}

/// Moves `positions` (of a primitive of `mesh`, drawn by `node`) by its morph targets'
/// POSITION displacements times their default weights: the node's, else the mesh's, else 0.
void morph(const GltfDocument& document, const Json& node, const Json& mesh, const Json& primitive,
  std::size_t meshIndex, std::vector<double>& positions)
{
  const auto targets = primitive.find("targets");
  const Json* weights = node.contains("weights") ? &node["weights"]
    : mesh.contains("weights")                   ? &mesh["weights"]
                                                 : nullptr;
  if (targets == primitive.end() || !weights)
  {
    return;
  }
  const std::string where = "meshes[" + std::to_string(meshIndex) + "]";
  if (!weights->is_array() || weights->size() != targets->size())
  {
    document.fail(where + " has " + std::to_string(targets->size()) +
      " morph targets but its (or its node's) weights are not as many numbers");
  }
  for (std::size_t t = 0; t < targets->size(); ++t)
  {
    const Json& weight = (*weights)[t];
    if (!weight.is_number() || !std::isfinite(weight.get<double>()))
    {
      document.fail(
        where + ": the weight of morph target " + std::to_string(t) + " is not a finite number");
    }
    const double w = weight.get<double>();
    const Json& target = (*targets)[t];
    if (w == 0 || !target.contains("POSITION"))
    {
      continue;
    }
    std::size_t components = 0;
    const std::vector<double> moved =
      document.accessor(target["POSITION"].get<std::size_t>(), components);
    if (components != 3 || moved.size() != positions.size())
    {
      document.fail(where + ": morph target " + std::to_string(t) +
        " does not move every vertex of its primitive by a VEC3");
    }
    for (std::size_t i = 0; i < positions.size(); ++i)
    {
      positions[i] += w * moved[i];
    }
  }
}

/// The punctual lights the file declares (KHR_lights_punctual), which are not read.
std::size_t punctualLights(const Json& root)
{
  const auto extensions = root.find("extensions");
  if (extensions == root.end() || !extensions->is_object())
  {
    return 0;
  }
  const auto lights = extensions->find("KHR_lights_punctual");
  if (lights == extensions->end() || !lights->is_object())
  {
    return 0;
  }
  const auto list = lights->find("lights");
  return list != lights->end() && list->is_array() ? list->size() : 0;
}

Scene readGltfDocument(const Json& root, const std::string& path, bool glb, std::string bin,
  std::int64_t binBytes, const Warn& warn, ProgressPoll& poll, const MemoryBudget& budget)
{
  GltfChecks checks(root, path);
  checks.run(glb, binBytes);
  std::size_t surfaces = 0, others = 0;
  for (const auto& mesh : checks.array("meshes"))
  {
    for (const auto& primitive : mesh["primitives"])
    {
      (checks.integer(primitive, "mode", "a primitive", 4) >= 4 ? surfaces : others) += 1;
    }
  }
  if (surfaces == 0)
  {
    throw FileError("the glTF file " + named(path) + " has no triangles" +
      (others > 0 ? " (only points or lines: " + std::to_string(others) + " primitives)"
                  : std::string()) +
      ": there is no surface to light");
  }
  poll(0.1);
  const GltfDocument document(root, path, std::move(bin));
  poll(0.3);

  // The nodes to draw: the default scene's (or the first scene's), else every root node.
  std::vector<std::int64_t> roots;
  const Json& scenes = checks.array("scenes");
  if (!scenes.empty())
  {
    const std::size_t scene =
      static_cast<std::size_t>(std::max<std::int64_t>(0, checks.integer(root, "scene", "", 0)));
    for (const auto& node : scenes[scene].value("nodes", Json::array()))
    {
      roots.push_back(node.get<std::int64_t>());
    }
  }
  else
  {
    for (std::size_t i = 0; i < checks.Parents.size(); ++i)
    {
      if (checks.Parents[i] < 0)
      {
        roots.push_back(static_cast<std::int64_t>(i));
      }
    }
  }

  const auto [drawnPoints, drawnTriangles] = drawnSize(checks, roots);
  checkOutputSize(path, "glTF", drawnPoints, drawnTriangles, budget);

  Scene scene;
  scene.format = "glTF";
  scene.points = vtkSmartPointer<vtkPoints>::New();
  scene.points->SetDataTypeToDouble();
  scene.polygons = vtkSmartPointer<vtkCellArray>::New();
  std::map<std::int64_t, int> materialIds; // glTF material (-1: the default) -> output material
  std::vector<std::int64_t> materialOrder;
  std::vector<std::array<double, 3>> vertexColourOfCell;
  std::vector<char> cellHasColour;
  // Output materials some of whose cells have no COLOR_0, which take the material's own
  // (clamped) reflectance; the others' cells take the product of their factor and colours.
  std::vector<char> usedWithoutColour;
  bool anyColour = false;
  std::size_t skippedPrimitives = 0;
  const Json& nodes = checks.array("nodes");
  const Json& meshes = checks.array("meshes");

  // Depth first, with the transform down to each node (the hierarchy is a checked forest).
  std::array<double, 16> identity{};
  identity[0] = identity[5] = identity[10] = identity[15] = 1;
  std::vector<std::pair<std::size_t, std::array<double, 16>>> stack;
  std::size_t visited = 0;
  for (auto it = roots.rbegin(); it != roots.rend(); ++it)
  {
    stack.emplace_back(static_cast<std::size_t>(*it), identity);
  }
  while (!stack.empty())
  {
    const auto [nodeIndex, parent] = stack.back();
    stack.pop_back();
    poll(0.3 +
      0.6 * static_cast<double>(visited++) /
        static_cast<double>(std::max<std::size_t>(1, nodes.size())));
    const Json& node = nodes[nodeIndex];
    const std::array<double, 16> nodeMatrix = multiply(parent, document.localTransform(nodeIndex));
    const Json children = node.value("children", Json::array());
    for (auto child = children.rbegin(); child != children.rend(); ++child)
    {
      stack.emplace_back(child->get<std::size_t>(), nodeMatrix);
    }
    if (!node.contains("mesh"))
    {
      continue;
    }
    const std::size_t meshIndex = node["mesh"].get<std::size_t>();
    for (const auto& instance : instanceTransforms(document, checks, node, nodeIndex))
    {
      const std::array<double, 16> matrix = multiply(nodeMatrix, instance);
      // A transform that mirrors (negative determinant) turns counter-clockwise into clockwise:
      // glTF then takes the clockwise side as the front (a mirrored lamp still lights outward).
      const bool mirrored = matrix[0] * (matrix[5] * matrix[10] - matrix[6] * matrix[9]) -
          matrix[1] * (matrix[4] * matrix[10] - matrix[6] * matrix[8]) +
          matrix[2] * (matrix[4] * matrix[9] - matrix[5] * matrix[8]) <
        0;
      for (const Json& primitive : meshes[meshIndex]["primitives"])
      {
        const std::int64_t mode = primitive.value("mode", std::int64_t(4));
        if (mode < 4)
        {
          ++skippedPrimitives;
          continue;
        }
        const Json& attributes = primitive["attributes"];
        std::size_t components = 0;
        std::vector<double> positions =
          document.accessor(attributes["POSITION"].get<std::size_t>(), components);
        const std::size_t vertexCount = positions.size() / 3;
        morph(document, node, meshes[meshIndex], primitive, meshIndex, positions);
        std::vector<std::size_t> indices;
        if (primitive.contains("indices"))
        {
          for (double index :
            document.accessor(primitive["indices"].get<std::size_t>(), components))
          {
            if (index >= static_cast<double>(vertexCount))
            {
              document.fail("a primitive of meshes[" + std::to_string(meshIndex) +
                "] names vertex " + std::to_string(static_cast<std::uint64_t>(index)) +
                " but its POSITION has " + std::to_string(vertexCount));
            }
            indices.push_back(static_cast<std::size_t>(index));
          }
        }
        else
        {
          for (std::size_t i = 0; i < vertexCount; ++i)
          {
            indices.push_back(i);
          }
        }
        std::vector<std::array<std::size_t, 3>> triangles;
        for (std::size_t i = 0; i + 2 < indices.size(); i += mode == 4 ? 3 : 1)
        {
          if (mode == 4)
          {
            triangles.push_back({ { indices[i], indices[i + 1], indices[i + 2] } });
          }
          else if (mode == 5) // strip: every other triangle turns the other way
          {
            triangles.push_back(i % 2 == 0
                ? std::array<std::size_t, 3>{ { indices[i], indices[i + 1], indices[i + 2] } }
                : std::array<std::size_t, 3>{ { indices[i + 1], indices[i], indices[i + 2] } });
          }
          else // fan
          {
            triangles.push_back({ { indices[0], indices[i + 1], indices[i + 2] } });
          }
        }
        const std::int64_t gltfMaterial = primitive.value("material", std::int64_t(-1));
        const auto found = materialIds.find(gltfMaterial);
        int material = 0;
        if (found != materialIds.end())
        {
          material = found->second;
        }
        else
        {
          material = static_cast<int>(materialOrder.size());
          materialIds[gltfMaterial] = material;
          materialOrder.push_back(gltfMaterial);
          usedWithoutColour.push_back(0);
        }
        std::vector<double> colours;
        std::size_t colourComponents = 0;
        if (attributes.contains("COLOR_0"))
        {
          colours = document.accessor(attributes["COLOR_0"].get<std::size_t>(), colourComponents);
          if (colourComponents < 3 || colours.size() / colourComponents != vertexCount)
          {
            document.fail("a primitive of meshes[" + std::to_string(meshIndex) +
              "] has a COLOR_0 that is not one RGB or RGBA colour per vertex");
          }
        }
        if (colours.empty() && !triangles.empty())
        {
          usedWithoutColour[static_cast<std::size_t>(material)] = 1;
        }
        // Only the vertices the triangles use, each once: primitives often share one POSITION
        // accessor of the whole mesh (an exporter's single vertex buffer), which copied whole
        // per primitive made 86 primitives of a 560,569-vertex buffer 48 million points.
        std::vector<vtkIdType> pointOf(vertexCount, -1);
        for (const auto& triangle : triangles)
        {
          for (const std::size_t v : triangle)
          {
            pointOf[v] = 0;
          }
        }
        for (std::size_t v = 0; v < vertexCount; ++v)
        {
          if (pointOf[v] < 0)
          {
            continue;
          }
          double p[3];
          for (std::size_t r = 0; r < 3; ++r)
          {
            p[r] = matrix[4 * r] * positions[3 * v] + matrix[4 * r + 1] * positions[3 * v + 1] +
              matrix[4 * r + 2] * positions[3 * v + 2] + matrix[4 * r + 3];
          }
          if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
          {
            document.fail(
              "meshes[" + std::to_string(meshIndex) + "] has a vertex that is not a finite point");
          }
          pointOf[v] = scene.points->InsertNextPoint(p);
        }
        for (const auto& triangle : triangles)
        {
          const vtkIdType ids[3] = { pointOf[triangle[0]], pointOf[triangle[mirrored ? 2 : 1]],
            pointOf[triangle[mirrored ? 1 : 2]] };
          scene.polygons->InsertNextCell(3, ids);
          scene.materialOfCell.push_back(material);
          std::array<double, 3> mean{ { 1, 1, 1 } };
          if (!colours.empty())
          {
            anyColour = true;
            for (std::size_t c = 0; c < 3; ++c)
            {
              mean[c] = (colours[triangle[0] * colourComponents + c] +
                          colours[triangle[1] * colourComponents + c] +
                          colours[triangle[2] * colourComponents + c]) /
                3.0;
            }
          }
          vertexColourOfCell.push_back(mean);
          cellHasColour.push_back(colours.empty() ? 0 : 1);
        }
      }
    }
  }
  if (scene.polygons->GetNumberOfCells() == 0)
  {
    throw FileError("the glTF file " + named(path) + " has no triangles in its scene" +
      (skippedPrimitives > 0
          ? " (only points or lines: " + std::to_string(skippedPrimitives) + " primitives)"
          : std::string()) +
      ": there is no surface to light");
  }
  if (skippedPrimitives > 0)
  {
    warn("the glTF file " + named(path) + " has " + std::to_string(skippedPrimitives) +
      " primitives of points or lines: they are skipped, only triangles are surfaces");
  }
  // Skins and animations move vertices; the rest pose is what is read (morph targets at
  // their default weights).
  if (!checks.array("skins").empty() || !checks.array("animations").empty())
  {
    warn("the glTF file " + named(path) +
      " has skins or animations: the meshes are read in their rest pose");
  }
  if (const std::size_t lights = punctualLights(root); lights > 0)
  {
    warn("the glTF file " + named(path) + " has " +
      (lights == 1 ? std::string("a punctual light (KHR_lights_punctual): it is")
                   : std::to_string(lights) + " punctual lights (KHR_lights_punctual): they are") +
      " not read; the lights are the light input, an emissive material or the sun");
  }

  // Materials, in order of first use; names unique (glTF names are optional and may repeat).
  const Json& materials = checks.array("materials");
  std::set<std::string> names;
  auto failMaterial = [&](const std::string& problem) { document.fail(problem); };
  std::vector<std::string> seeThrough;
  // The factor (times the texture's mean) of each output material before it is clamped: COLOR_0
  // multiplies it, and only the product is clamped (a white default material under colours of
  // 0.2 reflects 0.2, not 0.198, and is not warned of).
  std::vector<std::array<double, 3>> unclamped;
  const Warn ignore = [](const std::string&) {};
  for (const std::int64_t gltfIndex : materialOrder)
  {
    Material material;
    const Warn& warnOfClamping = usedWithoutColour[unclamped.size()] ? warn : ignore;
    if (gltfIndex < 0)
    {
      material.name = "default";
      unclamped.push_back({ { 1, 1, 1 } });
      material.reflectance = checkedReflectance(unclamped.back(),
        "the glTF default material (of primitives without a material) in " + named(path),
        warnOfClamping);
    }
    else
    {
      const Json& source = materials[static_cast<std::size_t>(gltfIndex)];
      const std::string where = "materials[" + std::to_string(gltfIndex) + "]";
      const auto name = source.find("name");
      material.name = name != source.end() && name->is_string() && !name->get<std::string>().empty()
        ? name->get<std::string>()
        : "material_" + std::to_string(gltfIndex);
      const std::string what = "the glTF material " + named(material.name) + " of " + named(path);
      // The diffuse colour of KHR_materials_pbrSpecularGlossiness, when the material has it,
      // as its readers take it before the metal-rough fallback (Sketchfab's and older
      // exporters' files have no other); else the base colour.
      const Json extensions = source.value("extensions", Json::object());
      const bool specularGlossiness = extensions.is_object() &&
        extensions.contains("KHR_materials_pbrSpecularGlossiness") &&
        extensions["KHR_materials_pbrSpecularGlossiness"].is_object();
      const Json pbr = specularGlossiness ? extensions["KHR_materials_pbrSpecularGlossiness"]
                                          : source.value("pbrMetallicRoughness", Json::object());
      const char* factorKey = specularGlossiness ? "diffuseFactor" : "baseColorFactor";
      const char* textureKey = specularGlossiness ? "diffuseTexture" : "baseColorTexture";
      std::array<double, 3> base = colourFactor(pbr, factorKey, 4, 1.0,
        where +
          (specularGlossiness ? ".extensions.KHR_materials_pbrSpecularGlossiness"
                              : ".pbrMetallicRoughness"),
        failMaterial);
      if (pbr.contains(textureKey))
      {
        const auto mean =
          document.textureMean(pbr[textureKey]["index"].get<std::size_t>(), what, warn);
        for (std::size_t c = 0; c < 3; ++c)
        {
          base[c] *= mean[c];
        }
      }
      unclamped.push_back(base);
      material.reflectance = checkedReflectance(base, what, warnOfClamping);
      // Cut-outs (leaves, fences), glass and curtains: a radiosity surface is opaque.
      const auto alpha = source.find("alphaMode");
      if ((alpha != source.end() && alpha->is_string() && *alpha != "OPAQUE") ||
        extensions.contains("KHR_materials_transmission"))
      {
        seeThrough.push_back(named(material.name));
      }
      double strength = 1.0;
      const Json extension = extensions.value("KHR_materials_emissive_strength", Json::object());
      if (extension.contains("emissiveStrength"))
      {
        const Json& value = extension["emissiveStrength"];
        if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0)
        {
          document.fail(where +
            ".extensions.KHR_materials_emissive_strength.emissiveStrength must be a number, 0 or "
            "more");
        }
        strength = value.get<double>();
      }
      material.radiance = colourFactor(source, "emissiveFactor", 3, 0.0, where, failMaterial);
      for (double& value : material.radiance)
      {
        value *= strength;
      }
      if (source.contains("emissiveTexture") &&
        material.radiance != std::array<double, 3>{ { 0, 0, 0 } })
      {
        const auto mean =
          document.textureMean(source["emissiveTexture"]["index"].get<std::size_t>(), what, warn);
        for (std::size_t c = 0; c < 3; ++c)
        {
          material.radiance[c] *= mean[c];
        }
      }
    }
    std::string unique = material.name;
    for (int n = 2; !names.insert(unique).second; ++n)
    {
      unique = material.name + "_" + std::to_string(n);
    }
    material.name = unique;
    scene.materials.push_back(material);
  }
  if (!seeThrough.empty())
  {
    std::string list;
    for (std::size_t i = 0; i < std::min<std::size_t>(seeThrough.size(), 3); ++i)
    {
      list += (i > 0 ? ", " : "") + seeThrough[i];
    }
    warn("the glTF file " + named(path) + " has " + std::to_string(seeThrough.size()) +
      " material(s) that let light through (alphaMode MASK or BLEND, or "
      "KHR_materials_transmission): " +
      list + (seeThrough.size() > 3 ? " ..." : "") +
      "; they are read as opaque: they block all the light that reaches them");
  }
  if (anyColour)
  {
    std::size_t clamped = 0;
    scene.cellReflectance.resize(vertexColourOfCell.size());
    for (std::size_t cell = 0; cell < vertexColourOfCell.size(); ++cell)
    {
      const std::size_t material = static_cast<std::size_t>(scene.materialOfCell[cell]);
      if (!cellHasColour[cell])
      {
        scene.cellReflectance[cell] = scene.materials[material].reflectance;
        continue;
      }
      const auto& base = unclamped[material];
      for (std::size_t c = 0; c < 3; ++c)
      {
        const double value = std::max(0.0, base[c] * vertexColourOfCell[cell][c]);
        clamped += value > MaxReflectance ? 1 : 0;
        scene.cellReflectance[cell][c] = std::min(value, MaxReflectance);
      }
    }
    if (clamped > 0)
    {
      warn("the glTF file " + named(path) + ": " + std::to_string(clamped) +
        " reflectance components of cells coloured by COLOR_0 are clamped to 0.99");
    }
  }
  poll(1.0);
  return scene;
}

} // namespace

Scene readGltf(
  const std::string& path, const Warn& warn, const Progress& progress, const MemoryBudget& budget)
{
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
    [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  const bool glb = extension == ".glb";
  ProgressPoll poll(progress, 0.0, 1.0);

  std::string bin;
  std::int64_t binBytes = -1;
  const Json root = readGltfJson(path, glb, bin, binBytes);
  try
  {
    return readGltfDocument(root, path, glb, std::move(bin), binBytes, warn, poll, budget);
  }
  catch (const Json::exception& e)
  {
    // A member of an unexpected JSON type that the checks above did not look at.
    throw FileError("the glTF file " + named(path) + " is malformed: " + e.what());
  }
}

} // namespace mlr::scenefile
