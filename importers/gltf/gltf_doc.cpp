#include "gltf_doc.h"

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "attribute_name.h"
#include "base/shim_error.h"
#include "gltf_meshopt.h"

extern "C" const char *const ptr_gltf_extensions[]; /* importer.h */

// A file's bytes: mapped where it can be, so that a .glb's BIN chunk or an
// external buffer is read where it lies (and its pages given back as the
// importer is done with them: see gltf_doc_release); read into memory where
// not (a pipe).
class FileBytes {
public:
    FileBytes() = default;
    FileBytes(const FileBytes &) = delete;
    FileBytes &operator=(const FileBytes &) = delete;
    ~FileBytes()
    {
        if (map_)
            munmap(map_, size_);
    }

    // False, with errno saying why, if the file cannot be read.
    bool open(const char *path) { return map(path) || read_all(path); }

    // False if the file is not a regular file that can be mapped. Opened
    // without blocking, so that a FIFO is refused rather than waited on.
    bool map(const char *path)
    {
        const int fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
        struct stat st;
        if (fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
            void *map = mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
            if (map != MAP_FAILED) {
                map_ = static_cast<unsigned char *>(map);
                size_ = size_t(st.st_size);
            }
        }
        if (fd >= 0)
            close(fd);
        return map_ != nullptr;
    }

    const unsigned char *data() const { return map_ ? map_ : read_.data(); }
    size_t size() const { return map_ ? size_ : read_.size(); }
    bool mapped() const { return map_ != nullptr; }

private:
    bool read_all(const char *path)
    {
        std::ifstream file(path, std::ios::binary);
        if (!file)
            return false;
        read_.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
        return !file.bad();
    }

    unsigned char *map_ = nullptr;
    size_t size_ = 0;
    std::vector<unsigned char> read_;
};

// A .gltf's (or .glb's) buffers in files of their own, mapped by ptr rather
// than read whole by tinygltf: for buffer b, file[b] (null where tinygltf
// read it), its byteLength, and the uri the JSON named before ptr gave
// tinygltf a stand-in.
struct ExternalBuffers {
    std::vector<std::unique_ptr<FileBytes>> file;
    std::vector<size_t> length;
    std::vector<std::string> uri;
};

struct GltfDoc {
    FileBytes file;
    ExternalBuffers external;
    tinygltf::Model model;
    std::vector<GltfBytes> buffers; /* each buffer's bytes (see gltf_meshopt.h) */
    int scene = -1;
    std::vector<std::string> files;
    std::map<int, std::vector<unsigned char>> decoded; /* buffer views, decompressed */
    std::map<int, std::vector<unsigned char>> image_files; /* images by URI, as read */
    std::vector<std::string> image_names; /* each image's, see GltfTexture */
};

namespace {

// Images are decoded by the importer, only those a sphere reads: here the
// bytes of those a URI names (a file, or data: text) are kept as read.
bool keep_image(tinygltf::Image *image, const int index, std::string *, std::string *, int, int,
                const unsigned char *bytes, int size, void *user)
{
    if (image->bufferView < 0) /* those in a buffer view are read there */
        (*static_cast<std::map<int, std::vector<unsigned char>> *>(user))[index]
            .assign(bytes, bytes + size);
    return true;
}

// tinygltf's file access, for the buffers ptr does not map and for images:
// regular files only. Its own opens whatever a URI names, so a URI naming a
// FIFO waits for a writer forever and one naming a folder reads as 2^63 bytes
// (lseek's end of a directory on ext4); to ptr both are files not found.
bool regular_file_exists(const std::string &path, void *)
{
    struct stat st;
    return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool read_regular_file(std::vector<unsigned char> *out, std::string *error,
                       const std::string &path, void *)
{
    FileBytes file;
    if (!file.map(path.c_str())) {
        *error = "not a regular file with bytes in it";
        return false;
    }
    out->assign(file.data(), file.data() + file.size());
    return true;
}

bool in_range(int index, size_t count) { return index >= 0 && size_t(index) < count; }

// The extension of image's format, for the image module: by its MIME type
// (a buffer view's, or a data: URI's), else its file's; PNG without either.
std::string image_extension(const tinygltf::Image &image)
{
    const std::string &uri = image.uri;
    if (image.mimeType.compare(0, 6, "image/") == 0)
        return image.mimeType.substr(6);
    if (uri.compare(0, 11, "data:image/") == 0)
        return uri.substr(11, uri.find(';') - 11);
    const size_t dot = uri.rfind('.');
    return dot == std::string::npos || uri.compare(0, 5, "data:") == 0 ? "png"
                                                                       : uri.substr(dot + 1);
}

const char *const instancing_extension = "EXT_mesh_gpu_instancing";

// The node's EXT_mesh_gpu_instancing attributes object, or null.
const tinygltf::Value *instancing_attributes(const tinygltf::Node &n)
{
    auto it = n.extensions.find(instancing_extension);
    if (it == n.extensions.end() || !it->second.IsObject() || !it->second.Has("attributes"))
        return nullptr;
    return &it->second.Get("attributes");
}

// An accessor index from an attributes object: -1 if absent, -2 if not an
// integer.
int attribute(const tinygltf::Value &attributes, const char *name)
{
    if (!attributes.Has(name))
        return -1;
    const tinygltf::Value &v = attributes.Get(name);
    return v.IsInt() && v.GetNumberAsInt() >= 0 ? v.GetNumberAsInt() : -2;
}

int primitive_attribute(const tinygltf::Primitive &p, const char *name)
{
    auto it = p.attributes.find(name);
    return it == p.attributes.end() ? -1 : it->second;
}

std::string required_extension_fault(const std::vector<std::string> &required)
{
    for (const std::string &name : required) {
        bool known = false;
        for (const char *const *e = ptr_gltf_extensions; *e; e++)
            known = known || name == *e;
        if (!known)
            return "requires the glTF extension " + name + ", which ptr does not implement";
    }
    return "";
}

// tinygltf leaves most cross-references unchecked; check every one ptr
// follows, so the C side can index without looking.
std::string check_indices(const tinygltf::Model &m, const std::vector<GltfBytes> &buffers,
                          const std::map<int, std::vector<unsigned char>> &decoded)
{
    const size_t nodes = m.nodes.size();
    for (size_t i = 0; i < nodes; i++) {
        const tinygltf::Node &n = m.nodes[i];
        if (n.mesh != -1 && !in_range(n.mesh, m.meshes.size()))
            return "node " + std::to_string(i) + " refers to mesh " + std::to_string(n.mesh) +
                   ", which does not exist";
        if (n.camera != -1 && !in_range(n.camera, m.cameras.size()))
            return "node " + std::to_string(i) + " refers to camera " +
                   std::to_string(n.camera) + ", which does not exist";
        for (int child : n.children)
            if (!in_range(child, nodes))
                return "node " + std::to_string(i) + " has child " + std::to_string(child) +
                       ", which does not exist";
        if (n.extensions.count(instancing_extension)) {
            const tinygltf::Value *a = instancing_attributes(n);
            if (!a || !a->IsObject() || n.mesh == -1)
                return "node " + std::to_string(i) + " has " + instancing_extension +
                       " without a mesh or without an attributes object";
            for (const char *name : { "TRANSLATION", "ROTATION", "SCALE", "_COLOR_0" }) {
                int index = attribute(*a, name);
                if (index == -2 || (index != -1 && !in_range(index, m.accessors.size())))
                    return "node " + std::to_string(i) + ": instance attribute " + name +
                           " refers to an accessor that does not exist";
            }
        }
        if (!(n.matrix.empty() || n.matrix.size() == 16) ||
            !(n.rotation.empty() || n.rotation.size() == 4) ||
            !(n.scale.empty() || n.scale.size() == 3) ||
            !(n.translation.empty() || n.translation.size() == 3))
            return "node " + std::to_string(i) + " has a transform of the wrong length";
    }
    for (size_t i = 0; i < m.meshes.size(); i++) {
        for (const tinygltf::Primitive &p : m.meshes[i].primitives) {
            if (p.material != -1 && !in_range(p.material, m.materials.size()))
                return "mesh " + std::to_string(i) + " refers to material " +
                       std::to_string(p.material) + ", which does not exist";
            if (p.indices != -1 && !in_range(p.indices, m.accessors.size()))
                return "mesh " + std::to_string(i) + " refers to index accessor " +
                       std::to_string(p.indices) + ", which does not exist";
            for (const auto &attr : p.attributes)
                if (!in_range(attr.second, m.accessors.size()))
                    return "mesh " + std::to_string(i) + " attribute " + attr.first +
                           " refers to accessor " + std::to_string(attr.second) +
                           ", which does not exist";
        }
    }
    // Accessors, views and buffers must lie inside one another, even where ptr
    // reads only the bounds: a file that lies about them is broken.
    for (size_t i = 0; i < m.bufferViews.size(); i++) {
        const tinygltf::BufferView &v = m.bufferViews[i];
        if (!in_range(v.buffer, m.buffers.size()))
            return "buffer view " + std::to_string(i) + " refers to buffer " +
                   std::to_string(v.buffer) + ", which does not exist";
        if (decoded.count(int(i))) /* its byteLength, decoded */
            continue;
        const size_t size = buffers[size_t(v.buffer)].size;
        if (v.byteOffset > size || v.byteLength > size - v.byteOffset)
            return "buffer view " + std::to_string(i) + " lies past the end of buffer " +
                   std::to_string(v.buffer) + " (" + std::to_string(size) + " bytes)";
    }
    for (size_t i = 0; i < m.accessors.size(); i++) {
        const tinygltf::Accessor &a = m.accessors[i];
        if (a.bufferView == -1)
            continue;
        if (!in_range(a.bufferView, m.bufferViews.size()))
            return "accessor " + std::to_string(i) + " refers to buffer view " +
                   std::to_string(a.bufferView) + ", which does not exist";
        const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
        const int stride = a.ByteStride(v);
        const int element = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)) *
                            tinygltf::GetNumComponentsInType(uint32_t(a.type));
        if (stride <= 0 || element <= 0)
            return "accessor " + std::to_string(i) + " has an unknown type or stride";
        // Last element's end, in 64 bits so that no count can wrap it.
        const unsigned long long end = a.count == 0 ? a.byteOffset
            : a.byteOffset + (unsigned long long)(a.count - 1) * unsigned(stride) + unsigned(element);
        if (end > v.byteLength)
            return "accessor " + std::to_string(i) + " reads past the end of buffer view " +
                   std::to_string(a.bufferView);
    }
    for (size_t s = 0; s < m.scenes.size(); s++)
        for (int root : m.scenes[s].nodes)
            if (!in_range(root, nodes))
                return "scene " + std::to_string(s) + " refers to node " + std::to_string(root) +
                       ", which does not exist";
    if (m.defaultScene != -1 && !in_range(m.defaultScene, m.scenes.size()))
        return "default scene " + std::to_string(m.defaultScene) + " does not exist";
    return "";
}

bool is_glb(const FileBytes &bytes)
{
    return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// What is wrong with a .glb's container, "" if nothing. tinygltf 2.7 lets a
// BIN chunk end up to 8 bytes past the data it is given (it leaves the
// chunk's own header out of its bound): such a file is refused before it
// gets there, and so is one shorter than its header says.
std::string glb_chunk_fault(const FileBytes &bytes)
{
    uint32_t header[5]; /* magic, version, length, JSON length, type */
    if (bytes.size() < sizeof header)
        return ""; /* tinygltf says what is wrong */
    std::memcpy(header, bytes.data(), sizeof header);
    const unsigned long long length = header[2], bin_at = 20ull + header[3];
    if (length > bytes.size())
        return "the file is shorter (" + std::to_string(bytes.size()) +
               " bytes) than its header says (" + std::to_string(length) + ")";
    if (bin_at + 8 > length)
        return ""; /* no BIN chunk, or tinygltf says what is wrong */
    uint32_t bin;
    std::memcpy(&bin, bytes.data() + bin_at, 4);
    return bin_at + 8 + bin > length ? "the BIN chunk runs past the end of the file" : "";
}

// Loads a .glb's bytes, or a .gltf's text, into model; false with *error set
// if tinygltf cannot.
bool load(tinygltf::TinyGLTF &loader, const unsigned char *data, size_t size, bool binary,
          const std::string &dir, tinygltf::Model *model, std::string *error)
{
    std::string warning;
    *model = tinygltf::Model();
    error->clear();
    return binary ? loader.LoadBinaryFromMemory(model, error, &warning, data, unsigned(size), dir)
                  : loader.LoadASCIIFromString(model, error, &warning,
                                               reinterpret_cast<const char *>(data),
                                               unsigned(size), dir);
}

// The JSON of a glTF file's bytes, where it lies: all of a .gltf, a .glb's
// JSON chunk (rest: where the chunks after it start). False if there is none.
bool json_of(const FileBytes &bytes, bool binary, std::string_view *json, size_t *rest)
{
    const unsigned char *b = bytes.data();
    if (!binary) {
        *json = std::string_view(reinterpret_cast<const char *>(b), bytes.size());
        *rest = bytes.size();
        return true;
    }
    uint32_t length = 0;
    if (bytes.size() < 20 || std::memcmp(b + 16, "JSON", 4) != 0)
        return false;
    std::memcpy(&length, b + 12, 4);
    if (length > bytes.size() - 20)
        return false;
    *json = std::string_view(reinterpret_cast<const char *>(b + 20), length);
    *rest = 20 + size_t(length);
    return true;
}

// A .glb of a JSON chunk json and the chunks rest (size bytes) after it.
std::vector<unsigned char> glb_of(std::string json, const unsigned char *rest, size_t size)
{
    json.resize((json.size() + 3) / 4 * 4, ' ');
    const uint32_t version = 2, json_length = uint32_t(json.size());
    const uint32_t total = uint32_t(20 + json.size() + size);
    unsigned char header[20];
    std::memcpy(&header[0], "glTF", 4);
    std::memcpy(&header[4], &version, 4);
    std::memcpy(&header[8], &total, 4);
    std::memcpy(&header[12], &json_length, 4);
    std::memcpy(&header[16], "JSON", 4);
    std::vector<unsigned char> out(header, header + sizeof header);
    out.reserve(total);
    out.insert(out.end(), json.begin(), json.end());
    out.insert(out.end(), rest, rest + size);
    return out;
}

// A mapped .glb's BIN chunk as buffer 0 (its first buffer, with no uri),
// which tinygltf would copy whole: that buffer cut to 4 bytes in doc (the
// JSON object tinygltf is given), and the chunk's bytes. False (doc
// untouched) if the file has no such buffer.
bool bin_kept_out(const FileBytes &bytes, size_t rest, nlohmann::json &doc, GltfBytes *bin)
{
    uint32_t chunk[2]; /* length, type */
    if (bytes.size() - rest < sizeof chunk + 4)
        return false;
    std::memcpy(chunk, bytes.data() + rest, sizeof chunk);
    if (std::memcmp(&chunk[1], "BIN", 4) != 0 || chunk[0] > bytes.size() - rest - sizeof chunk)
        return false;
    if (!doc.contains("buffers") || !doc["buffers"].is_array() || doc["buffers"].empty())
        return false;
    nlohmann::json &buffer = doc["buffers"][0];
    if (!buffer.is_object() || buffer.contains("uri") || !buffer.contains("byteLength") ||
        !buffer["byteLength"].is_number_unsigned() ||
        buffer["byteLength"].get<unsigned long long>() > chunk[0] ||
        buffer["byteLength"].get<unsigned long long>() < 4)
        return false;
    *bin = GltfBytes{ bytes.data() + rest + sizeof chunk,
                      size_t(buffer["byteLength"].get<unsigned long long>()) };
    buffer["byteLength"] = 4;
    return true;
}

// A URI's %XX escapes decoded, as tinygltf decodes a buffer's; false if one
// is malformed.
bool uri_decoded(const std::string &uri, std::string *out)
{
    out->clear();
    for (size_t i = 0; i < uri.size(); i++) {
        if (uri[i] != '%') {
            out->push_back(uri[i]);
            continue;
        }
        if (i + 2 >= uri.size() || !std::isxdigit(static_cast<unsigned char>(uri[i + 1])) ||
            !std::isxdigit(static_cast<unsigned char>(uri[i + 2])))
            return false;
        out->push_back(char(std::stoi(uri.substr(i + 1, 2), nullptr, 16)));
        i += 2;
    }
    return true;
}

// The buffers of a glTF JSON that name a file (not a data: URI), which
// tinygltf would read whole into memory: each that is a regular file at
// least its byteLength long is mapped into external and given to tinygltf as
// a 4-byte data: stand-in in doc (the JSON object tinygltf is given). The
// others are left to tinygltf, which reads them or says what is wrong with
// them. Returns whether any was.
bool external_buffers_kept_out(const std::string &dir, nlohmann::json &doc,
                               ExternalBuffers *external)
{
    if (!doc.contains("buffers") || !doc["buffers"].is_array())
        return false;
    nlohmann::json &buffers = doc["buffers"];
    external->file.resize(buffers.size());
    external->length.resize(buffers.size());
    external->uri.resize(buffers.size());
    bool any = false;
    for (size_t b = 0; b < buffers.size(); b++) {
        nlohmann::json &buffer = buffers[b];
        std::string name;
        if (!buffer.is_object() || !buffer.contains("uri") || !buffer["uri"].is_string() ||
            !buffer.contains("byteLength") || !buffer["byteLength"].is_number_unsigned())
            continue;
        const std::string uri = buffer["uri"].get<std::string>();
        const unsigned long long length = buffer["byteLength"].get<unsigned long long>();
        if (uri.compare(0, 5, "data:") == 0 || length < 4 || !uri_decoded(uri, &name) ||
            name.empty())
            continue;
        auto file = std::make_unique<FileBytes>();
        if (!file->map((name[0] == '/' ? name : dir + name).c_str()) || file->size() < length)
            continue;
        external->file[b] = std::move(file);
        external->length[b] = size_t(length);
        external->uri[b] = uri;
        buffer["uri"] = "data:application/octet-stream;base64,AAAAAA==";
        buffer["byteLength"] = 4;
        any = true;
    }
    return any;
}

const char *const draco_extension = "KHR_draco_mesh_compression";

// An object's extensions[name], or null.
const nlohmann::json *json_extension(const nlohmann::json &object, const char *name)
{
    if (!object.is_object() || !object.contains("extensions") ||
        !object["extensions"].is_object() || !object["extensions"].contains(name))
        return nullptr;
    return &object["extensions"][name];
}

// What tinygltf refuses of compressed files, taken out of their JSON object
// doc: the fallback buffers of EXT_meshopt_compression (no data: for
// loaders that cannot decode) get one byte, and primitives compressed by
// Draco lose their indices (an accessor without data, which ptr never
// reads). Returns whether anything was.
bool loadable_by_tinygltf(nlohmann::json &doc)
{
    bool any = false;
    if (doc.contains("buffers") && doc["buffers"].is_array())
        for (nlohmann::json &buffer : doc["buffers"]) {
            const nlohmann::json *ext = json_extension(buffer, meshopt_extension);
            if (ext && ext->is_object() && ext->value("fallback", false)) {
                buffer["byteLength"] = 1;
                buffer["uri"] = "data:application/octet-stream;base64,AA==";
                any = true;
            }
        }
    if (doc.contains("meshes") && doc["meshes"].is_array())
        for (nlohmann::json &mesh : doc["meshes"])
            if (mesh.is_object() && mesh.contains("primitives") && mesh["primitives"].is_array())
                for (nlohmann::json &primitive : mesh["primitives"])
                    if (json_extension(primitive, draco_extension))
                        any = primitive.erase("indices") > 0 || any;
    return any;
}

// The extensionsRequired of a glTF JSON object.
std::vector<std::string> required_extensions(const nlohmann::json &doc)
{
    std::vector<std::string> names;
    if (doc.contains("extensionsRequired") &&
        doc["extensionsRequired"].is_array())
        for (const nlohmann::json &name : doc["extensionsRequired"])
            if (name.is_string())
                names.push_back(name.get<std::string>());
    return names;
}

// Whether ptr may have to change a glTF JSON text before tinygltf loads it,
// from the text alone: a .glb's BIN chunk, a "uri" that is not a data: URI
// (a file, perhaps a buffer to map), or a compression extension. Where not,
// the text goes to tinygltf unparsed by ptr.
bool needs_changes(std::string_view json, bool binary)
{
    static const char uri[] = "\"uri\"";
    for (size_t at = json.find(uri); at != json.npos; at = json.find(uri, at + 1)) {
        const size_t value = json.find_first_not_of(" \t\r\n:", at + sizeof uri - 1);
        if (value == json.npos || json.compare(value, 6, "\"data:") != 0)
            return true;
    }
    return binary || json.find(meshopt_extension) != json.npos ||
           json.find(draco_extension) != json.npos;
}

const tinygltf::Value *object_member(const tinygltf::Value &object, const char *key)
{
    // Get(key) asserts on a non-object.
    if (!object.IsObject() || !object.Has(key))
        return nullptr;
    return &object.Get(key);
}

bool number_member(const tinygltf::Value &object, const char *key, double *out)
{
    const tinygltf::Value *v = object_member(object, key);
    if (!v || !v->IsNumber())
        return false;
    *out = v->GetNumberAsDouble();
    return true;
}

// A number inside material.extensions[extension][key].
bool extension_number(const tinygltf::ExtensionMap &extensions, const char *extension,
                      const char *key, double *out)
{
    auto it = extensions.find(extension);
    return it != extensions.end() && number_member(it->second, key, out);
}

// object[key] as two numbers into out, if it is an array of two numbers.
void pair_member(const tinygltf::Value &object, const char *key, double out[2])
{
    const tinygltf::Value *v = object_member(object, key);
    if (v && v->IsArray() && v->ArrayLen() == 2 && v->Get(0).IsNumber() && v->Get(1).IsNumber())
        for (int k = 0; k < 2; k++)
            out[k] = v->Get(k).GetNumberAsDouble();
}

// A textureInfo's texture and TEXCOORD_n, with its KHR_texture_transform.
void texture_ref(int index, int texcoord, const tinygltf::ExtensionMap &extensions,
                 GltfTextureRef *out)
{
    *out = GltfTextureRef{ index, texcoord, { 0, 0 }, 0, { 1, 1 } };
    auto it = extensions.find("KHR_texture_transform");
    if (it == extensions.end())
        return;
    const tinygltf::Value &t = it->second;
    double n;
    if (number_member(t, "texCoord", &n) && n >= 0 && n < 16)
        out->texcoord = int(n);
    number_member(t, "rotation", &out->rotation);
    pair_member(t, "offset", out->offset);
    pair_member(t, "scale", out->scale);
}

template <size_t N>
void copy_or(double (&dst)[N], const std::vector<double> &src, const double (&fallback)[N])
{
    for (size_t i = 0; i < N; i++)
        dst[i] = src.size() == N ? src[i] : fallback[i];
}

} // namespace

extern "C" const char *const ptr_gltf_extensions[] = {
    "EXT_mesh_gpu_instancing", "EXT_meshopt_compression", "KHR_draco_mesh_compression",
    "KHR_materials_emissive_strength", "KHR_materials_ior", "KHR_materials_transmission",
    "KHR_mesh_quantization", "KHR_texture_transform", nullptr,
};

extern "C" GltfDoc *gltf_doc_load(const char *path, PtrError *err)
{
    try {
        auto doc = std::make_unique<GltfDoc>();
        const FileBytes &bytes = doc->file;
        if (!doc->file.open(path)) {
            ptr_shim_error(err, PTR_ERR_SCENE_UNREADABLE,
                           std::string(path) + ": " + std::strerror(errno));
            return nullptr;
        }
        const bool binary = is_glb(bytes);
        // External buffers' URIs are relative to the .gltf's folder.
        const std::string scene_path = path;
        const size_t slash = scene_path.rfind('/');
        const std::string dir = slash == std::string::npos ? "" : scene_path.substr(0, slash + 1);
        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(keep_image, &doc->image_files);
        loader.SetFsCallbacks({ regular_file_exists, tinygltf::ExpandFilePath, read_regular_file,
                                tinygltf::WriteWholeFile, nullptr });
        std::string error;
        std::string fault = bytes.size() > UINT32_MAX ? "larger than 4 GiB, the most glTF holds"
                            : binary                  ? glb_chunk_fault(bytes)
                                                      : "";
        std::string_view json;
        size_t rest = 0;
        const bool has_json = fault.empty() && json_of(bytes, binary, &json, &rest);
        // The JSON as ptr reads and changes it, parsed when first needed
        // and never again: all that reads or changes the JSON works on this
        // document, and tinygltf parses only the text it is given.
        std::optional<nlohmann::json> parsed_json;
        const auto parsed = [&]() -> nlohmann::json & {
            if (!parsed_json)
                parsed_json = nlohmann::json::parse(json.begin(), json.end(), nullptr, false);
            return *parsed_json;
        };
        const bool object = has_json && needs_changes(json, binary) && parsed().is_object();
        GltfBytes bin = { nullptr, 0 };
        const bool bin_mapped = object && binary && bytes.mapped() &&
                                bin_kept_out(bytes, rest, parsed(), &bin);
        const bool external_mapped =
            object && external_buffers_kept_out(dir, parsed(), &doc->external);
        const bool loadable = object && loadable_by_tinygltf(parsed());
        bool ok = false;
        if (fault.empty() && !bin_mapped && !external_mapped && !loadable) {
            ok = load(loader, bytes.data(), bytes.size(), binary, dir, &doc->model, &error);
        } else if (fault.empty()) {
            // The JSON as changed, with the file's other chunks after it, or
            // with a .glb's BIN chunk mapped, a 4-byte stand-in for it.
            static const unsigned char stand_in[12] = { 4, 0, 0, 0, 'B', 'I', 'N', 0 };
            const std::string text = parsed().dump();
            if (binary) {
                const std::vector<unsigned char> glb =
                    bin_mapped ? glb_of(text, stand_in, sizeof stand_in)
                               : glb_of(text, bytes.data() + rest, bytes.size() - rest);
                ok = load(loader, glb.data(), glb.size(), true, dir, &doc->model, &error);
            } else {
                ok = load(loader, reinterpret_cast<const unsigned char *>(text.data()),
                          text.size(), false, dir, &doc->model, &error);
            }
        }
        // tinygltf stops at what it cannot load before ptr sees the
        // extensions: say first what the file requires that ptr lacks.
        if (!ok && has_json && parsed().is_object())
            fault = required_extension_fault(required_extensions(parsed()));
        if (!ok && fault.empty())
            fault = error.empty() ? "not a valid glTF file" : error;
        if (fault.empty())
            fault = required_extension_fault(doc->model.extensionsRequired);
        const ExternalBuffers &external = doc->external;
        for (size_t b = 0; ok && b < doc->model.buffers.size(); b++) {
            const std::vector<unsigned char> &copy = doc->model.buffers[b].data;
            const bool mapped = b < external.file.size() && external.file[b];
            doc->buffers.push_back(b == 0 && bin_mapped ? bin
                                   : mapped ? GltfBytes{ external.file[b]->data(), external.length[b] }
                                            : GltfBytes{ copy.data(), copy.size() });
        }
        if (fault.empty())
            fault = meshopt_decode(doc->model, doc->buffers, doc->decoded);
        if (fault.empty())
            fault = check_indices(doc->model, doc->buffers, doc->decoded);
        if (!fault.empty()) {
            ptr_shim_error(err, PTR_ERR_SCENE_INVALID, std::string(path) + ": " + fault);
            return nullptr;
        }
        const tinygltf::Model &m = doc->model;
        doc->scene = m.defaultScene != -1 ? m.defaultScene : (m.scenes.empty() ? -1 : 0);
        for (size_t i = 0; i < m.images.size(); i++) /* "FILE image 3.png" */
            doc->image_names.push_back(std::string(path) + " image " + std::to_string(i) + "." +
                                       image_extension(m.images[i]));
        for (size_t b = 0; b < m.buffers.size(); b++) {
            const std::string &uri = b < external.uri.size() && !external.uri[b].empty()
                                         ? external.uri[b] : m.buffers[b].uri;
            if (!uri.empty() && uri.compare(0, 5, "data:") != 0)
                doc->files.push_back(uri[0] == '/' ? uri : dir + uri);
        }
        return doc.release();
    } catch (...) {
        ptr_shim_caught(err, PTR_ERR_SCENE_INVALID, path);
    }
    return nullptr;
}

extern "C" void gltf_doc_free(GltfDoc *doc) { delete doc; }

extern "C" size_t gltf_doc_file_count(const GltfDoc *d) { return d->files.size(); }
extern "C" const char *gltf_doc_file(const GltfDoc *d, size_t i) { return d->files[i].c_str(); }
extern "C" size_t gltf_doc_node_count(const GltfDoc *d) { return d->model.nodes.size(); }
extern "C" size_t gltf_doc_mesh_count(const GltfDoc *d) { return d->model.meshes.size(); }
extern "C" size_t gltf_doc_material_count(const GltfDoc *d) { return d->model.materials.size(); }
extern "C" size_t gltf_doc_texture_count(const GltfDoc *d) { return d->model.textures.size(); }

extern "C" void gltf_doc_node(const GltfDoc *doc, size_t index, GltfNode *out)
{
    static const double identity[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
    static const double zero3[3] = { 0, 0, 0 }, one3[3] = { 1, 1, 1 };
    static const double unit_quat[4] = { 0, 0, 0, 1 };
    const tinygltf::Node &n = doc->model.nodes[index];
    *out = GltfNode{};
    out->name = n.name.c_str();
    out->mesh = n.mesh;
    out->camera = n.camera;
    out->children = n.children.data();
    out->child_count = n.children.size();
    out->has_matrix = n.matrix.size() == 16;
    copy_or(out->matrix, n.matrix, identity);
    copy_or(out->translation, n.translation, zero3);
    copy_or(out->rotation, n.rotation, unit_quat);
    copy_or(out->scale, n.scale, one3);
    out->has_radius = number_member(n.extras, "radius", &out->radius);
    if (const tinygltf::Value *a = instancing_attributes(n)) {
        out->instanced = 1;
        out->instances = GltfInstancing{ attribute(*a, "TRANSLATION"), attribute(*a, "ROTATION"),
                                         attribute(*a, "SCALE"), attribute(*a, "_COLOR_0") };
    }
}

extern "C" void gltf_doc_mesh(const GltfDoc *doc, size_t index, GltfMesh *out)
{
    const tinygltf::Mesh &mesh = doc->model.meshes[index];
    *out = GltfMesh{};
    out->name = mesh.name.c_str();
    out->material = -1;
    out->primitive_count = mesh.primitives.size();
    out->has_bounds = 1;
    for (int k = 0; k < 3; k++) {
        out->min[k] = HUGE_VAL;
        out->max[k] = -HUGE_VAL;
    }
    for (const tinygltf::Primitive &p : mesh.primitives) {
        if (p.mode == TINYGLTF_MODE_POINTS) {
            out->point_primitives++;
            continue;
        }
        if (!out->has_surface)
            out->material = p.material;
        out->has_surface = 1;
        auto pos = p.attributes.find("POSITION");
        if (pos == p.attributes.end()) {
            out->has_bounds = 0;
            continue;
        }
        const tinygltf::Accessor &a = doc->model.accessors[size_t(pos->second)];
        if (a.minValues.size() != 3 || a.maxValues.size() != 3) {
            out->has_bounds = 0;
            continue;
        }
        for (size_t k = 0; k < 3; k++) {
            out->min[k] = std::min(out->min[k], gltf_component_value(a.componentType, a.normalized,
                                                                     a.minValues[k]));
            out->max[k] = std::max(out->max[k], gltf_component_value(a.componentType, a.normalized,
                                                                     a.maxValues[k]));
        }
    }
}

extern "C" void gltf_doc_primitive(const GltfDoc *doc, size_t mesh, size_t index,
                                   GltfPrimitive *out)
{
    const tinygltf::Primitive &p = doc->model.meshes[mesh].primitives[index];
    *out = GltfPrimitive{ p.mode == TINYGLTF_MODE_POINTS, p.material,
                          primitive_attribute(p, "POSITION"), primitive_attribute(p, "_RADIUS"),
                          primitive_attribute(p, "COLOR_0"),
                          p.extensions.count(draco_extension) > 0, p.mode, p.indices };
}

extern "C" int gltf_doc_instance_attribute(const GltfDoc *doc, size_t node, const char *name)
{
    const tinygltf::Value *a = instancing_attributes(doc->model.nodes[node]);
    if (!a || !a->IsObject())
        return -1;
    for (const std::string &key : a->Keys())
        if (ptr_attribute_named(key.c_str(), name)) {
            int index = attribute(*a, key.c_str());
            return in_range(index, doc->model.accessors.size()) ? index : -2;
        }
    return -1;
}

extern "C" int gltf_doc_primitive_attribute(const GltfDoc *doc, size_t mesh, size_t index,
                                            const char *name)
{
    for (const auto &attr : doc->model.meshes[mesh].primitives[index].attributes)
        if (ptr_attribute_named(attr.first.c_str(), name))
            return attr.second; /* every primitive attribute was checked at load */
    return -1;
}

extern "C" void gltf_doc_custom_attributes(const GltfDoc *doc, char *out, size_t size)
{
    std::vector<std::string> names;
    auto note = [&names](const std::string &name) {
        if (name[0] == '_' && std::find(names.begin(), names.end(), name) == names.end())
            names.push_back(name);
    };
    for (const tinygltf::Node &n : doc->model.nodes)
        if (const tinygltf::Value *a = instancing_attributes(n))
            if (a->IsObject())
                for (const std::string &key : a->Keys())
                    note(key);
    for (const tinygltf::Mesh &mesh : doc->model.meshes)
        for (const tinygltf::Primitive &p : mesh.primitives)
            for (const auto &attr : p.attributes)
                note(attr.first);
    std::string list;
    for (const std::string &name : names)
        list += (list.empty() ? "" : ", ") + name;
    snprintf(out, size, "%s", list.c_str());
}

extern "C" void gltf_doc_accessor(const GltfDoc *doc, size_t index, GltfAccessor *out)
{
    const tinygltf::Model &m = doc->model;
    const tinygltf::Accessor &a = m.accessors[index];
    *out = GltfAccessor{};
    out->count = a.count;
    out->component_type = a.componentType;
    const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    out->components = components >= 1 && components <= 4 && a.type != TINYGLTF_TYPE_MAT2
                          ? components : 0;
    out->normalized = a.normalized;
    out->sparse = a.sparse.isSparse;
    if (a.bufferView == -1 || out->sparse)
        return;
    const tinygltf::BufferView &v = m.bufferViews[size_t(a.bufferView)];
    out->stride = size_t(a.ByteStride(v));
    auto decoded = doc->decoded.find(a.bufferView);
    out->data = decoded != doc->decoded.end()
                    ? decoded->second.data() + a.byteOffset
                    : doc->buffers[size_t(v.buffer)].data + v.byteOffset + a.byteOffset;
}

// The mapped file a's elements lie in, or null.
static const FileBytes *mapping_of(const GltfDoc *doc, const GltfAccessor *a)
{
    const auto holds = [a](const FileBytes &f) {
        return f.mapped() && a->data >= f.data() && a->data < f.data() + f.size();
    };
    if (holds(doc->file))
        return &doc->file;
    for (const auto &f : doc->external.file)
        if (f && holds(*f))
            return f.get();
    return nullptr;
}

extern "C" void gltf_doc_release(const GltfDoc *doc, const GltfAccessor *a, size_t first,
                                 size_t end)
{
    const FileBytes *file = a->data ? mapping_of(doc, a) : nullptr;
    if (!file || first >= end)
        return;
    // The whole pages between, and only within the mapping.
    const uintptr_t page = uintptr_t(sysconf(_SC_PAGESIZE));
    const uintptr_t map_lo = uintptr_t(file->data()), map_hi = map_lo + file->size();
    const uintptr_t lo = std::max(uintptr_t(a->data) + first * a->stride, map_lo);
    const uintptr_t hi = std::min(uintptr_t(a->data) + end * a->stride, map_hi);
    const uintptr_t from = (lo + page - 1) / page * page, to = hi / page * page;
    if (from < to)
        madvise(reinterpret_cast<void *>(from), to - from, MADV_DONTNEED);
}

extern "C" void gltf_doc_material(const GltfDoc *doc, size_t index, GltfMaterial *out)
{
    static const double white[4] = { 1, 1, 1, 1 }, black3[3] = { 0, 0, 0 };
    const tinygltf::Material &m = doc->model.materials[index];
    const tinygltf::PbrMetallicRoughness &pbr = m.pbrMetallicRoughness;
    *out = GltfMaterial{};
    out->name = m.name.c_str();
    copy_or(out->base_color, pbr.baseColorFactor, white);
    out->metallic = pbr.metallicFactor;
    out->roughness = pbr.roughnessFactor;
    copy_or(out->emissive, m.emissiveFactor, black3);
    out->emissive_strength = 1.0;
    extension_number(m.extensions, "KHR_materials_emissive_strength", "emissiveStrength",
                     &out->emissive_strength);
    out->transmission = 0.0;
    extension_number(m.extensions, "KHR_materials_transmission", "transmissionFactor",
                     &out->transmission);
    out->ior = 1.5;
    extension_number(m.extensions, "KHR_materials_ior", "ior", &out->ior);
    texture_ref(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                pbr.baseColorTexture.extensions, &out->base_texture);
    texture_ref(m.emissiveTexture.index, m.emissiveTexture.texCoord, m.emissiveTexture.extensions,
                &out->emissive_texture);
    texture_ref(pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
                pbr.metallicRoughnessTexture.extensions, &out->metal_rough_texture);
}

extern "C" void gltf_doc_texture(const GltfDoc *doc, int index, GltfTexture *out)
{
    const tinygltf::Model &m = doc->model;
    *out = GltfTexture{};
    out->wrap_s = out->wrap_t = GLTF_REPEAT;
    if (!in_range(index, m.textures.size())) {
        out->fault = "does not exist";
        return;
    }
    const tinygltf::Texture &t = m.textures[size_t(index)];
    if (in_range(t.sampler, m.samplers.size())) {
        out->wrap_s = m.samplers[size_t(t.sampler)].wrapS;
        out->wrap_t = m.samplers[size_t(t.sampler)].wrapT;
    }
    if (t.source < 0 && t.extensions.count("KHR_texture_basisu")) {
        out->fault = "is KTX2 (KHR_texture_basisu), which ptr does not read";
        return;
    }
    if (!in_range(t.source, m.images.size())) {
        out->fault = "refers to an image that does not exist";
        return;
    }
    const tinygltf::Image &image = m.images[size_t(t.source)];
    out->name = doc->image_names[size_t(t.source)].c_str();
    if (image.mimeType == "image/ktx2") {
        out->fault = "is KTX2 (KHR_texture_basisu), which ptr does not read";
        return;
    }
    auto file = doc->image_files.find(t.source);
    if (file != doc->image_files.end()) {
        out->bytes = file->second.data();
        out->size = file->second.size();
    } else if (in_range(image.bufferView, m.bufferViews.size())) {
        const tinygltf::BufferView &v = m.bufferViews[size_t(image.bufferView)];
        out->bytes = doc->buffers[size_t(v.buffer)].data + v.byteOffset; /* checked at load */
        out->size = v.byteLength;
    } else {
        out->fault = "has an image with no bytes ptr can read";
    }
}

extern "C" void gltf_doc_camera(const GltfDoc *doc, size_t index, GltfCamera *out)
{
    const tinygltf::Camera &c = doc->model.cameras[index];
    *out = GltfCamera{};
    out->name = c.name.c_str();
    out->perspective = c.type == "perspective";
    out->yfov = c.perspective.yfov;
    out->aspect_ratio = c.perspective.aspectRatio;
    out->xmag = c.orthographic.xmag;
    out->ymag = c.orthographic.ymag;
    out->znear = c.orthographic.znear;
    out->zfar = c.orthographic.zfar;
    out->has_aperture = number_member(c.extras, "aperture", &out->aperture);
    out->has_focus_distance = number_member(c.extras, "focus_distance", &out->focus_distance);
}

extern "C" int gltf_doc_scene(const GltfDoc *doc, GltfScene *out)
{
    *out = GltfScene{};
    if (doc->scene < 0)
        return 0;
    const tinygltf::Scene &s = doc->model.scenes[size_t(doc->scene)];
    out->roots = s.nodes.data();
    out->root_count = s.nodes.size();
    if (const tinygltf::Value *sky = object_member(s.extras, "sky")) {
        if (sky->IsString()) {
            out->sky_name = sky->Get<std::string>().c_str();
        } else if (sky->IsArray() && sky->ArrayLen() == 3 && sky->Get(0).IsNumber() &&
                   sky->Get(1).IsNumber() && sky->Get(2).IsNumber()) {
            out->has_sky_rgb = 1;
            for (int k = 0; k < 3; k++)
                out->sky_rgb[k] = sky->Get(k).GetNumberAsDouble();
        } else {
            out->sky_invalid = 1;
        }
    }
    if (const tinygltf::Value *res = object_member(s.extras, "resolution")) {
        if (res->IsArray() && res->ArrayLen() == 2 && res->Get(0).IsInt() &&
            res->Get(1).IsInt()) {
            out->has_resolution = 1;
            out->resolution[0] = res->Get(0).GetNumberAsInt();
            out->resolution[1] = res->Get(1).GetNumberAsInt();
        } else {
            out->resolution_invalid = 1;
        }
    }
    return 1;
}
