#include "gltf_meshopt.h"

#include <meshoptimizer.h>

#include <cstring>

const char *const meshopt_extension = "EXT_meshopt_compression";

namespace {

// A view's compressed stream and what it decodes to, as the extension
// describes them.
struct Stream {
    int buffer = -1;
    size_t offset = 0, length = 0, stride = 0, count = 0;
    std::string mode, filter = "NONE";
};

std::string view_error(size_t index, const std::string &what)
{
    return std::string(meshopt_extension) + ": buffer view " + std::to_string(index) + " " + what;
}

bool read_stream(const tinygltf::Value &ext, Stream *s)
{
    auto number = [&](const char *key, size_t *out, bool required) {
        if (!ext.Has(key))
            return !required;
        const tinygltf::Value &v = ext.Get(key);
        if (!v.IsInt() || v.GetNumberAsInt() < 0)
            return false;
        *out = size_t(v.GetNumberAsInt());
        return true;
    };
    size_t buffer = 0;
    if (!ext.IsObject() || !number("buffer", &buffer, true) ||
        !number("byteOffset", &s->offset, false) || !number("byteLength", &s->length, true) ||
        !number("byteStride", &s->stride, true) || !number("count", &s->count, true) ||
        !ext.Has("mode") || !ext.Get("mode").IsString())
        return false;
    s->buffer = int(buffer);
    s->mode = ext.Get("mode").Get<std::string>();
    if (ext.Has("filter")) {
        if (!ext.Get("filter").IsString())
            return false;
        s->filter = ext.Get("filter").Get<std::string>();
    }
    return true;
}

// The library asserts on parameters outside these (meshoptimizer.h): they are
// checked first, so that a hostile file is refused rather than abort ptr.
std::string stream_fault(const Stream &s)
{
    if (s.mode == "ATTRIBUTES") {
        if (s.stride == 0 || s.stride > 256 || s.stride % 4 != 0)
            return "has a byteStride the ATTRIBUTES mode does not allow";
    } else if (s.mode == "TRIANGLES" || s.mode == "INDICES") {
        if (s.stride != 2 && s.stride != 4)
            return "has an index size of neither 2 nor 4 bytes";
        if (s.mode == "TRIANGLES" && s.count % 3 != 0)
            return "holds triangles whose count is not a multiple of 3";
        if (s.filter != "NONE")
            return "filters indices";
    } else {
        return "has an unknown mode '" + s.mode + "'";
    }
    if (s.filter == "OCTAHEDRAL" ? s.stride != 4 && s.stride != 8
        : s.filter == "QUATERNION" ? s.stride != 8
        : s.filter == "EXPONENTIAL" ? s.stride % 4 != 0
        : s.filter != "NONE")
        return "has a filter '" + s.filter + "' it cannot take at that byteStride";
    return "";
}

void unfilter(const Stream &s, unsigned char *data)
{
    if (s.filter == "OCTAHEDRAL")
        meshopt_decodeFilterOct(data, s.count, s.stride);
    else if (s.filter == "QUATERNION")
        meshopt_decodeFilterQuat(data, s.count, s.stride);
    else if (s.filter == "EXPONENTIAL")
        meshopt_decodeFilterExp(data, s.count, s.stride);
}

} // namespace

std::string meshopt_decode(const tinygltf::Model &m, const std::vector<GltfBytes> &buffers,
                           std::map<int, std::vector<unsigned char>> &views)
{
    for (size_t i = 0; i < m.bufferViews.size(); i++) {
        const tinygltf::BufferView &view = m.bufferViews[i];
        auto it = view.extensions.find(meshopt_extension);
        if (it == view.extensions.end())
            continue;
        Stream s;
        if (!read_stream(it->second, &s))
            return view_error(i, "lacks a buffer, byteLength, byteStride, count or mode");
        std::string fault = stream_fault(s);
        if (!fault.empty())
            return view_error(i, fault);
        if (s.buffer >= int(m.buffers.size()))
            return view_error(i, "refers to buffer " + std::to_string(s.buffer) +
                                     ", which does not exist");
        const GltfBytes &source = buffers[size_t(s.buffer)];
        if (s.offset > source.size || s.length > source.size - s.offset)
            return view_error(i, "has a compressed stream past the end of buffer " +
                                     std::to_string(s.buffer));
        // In 64 bits, so that no count can wrap the product.
        const unsigned long long decoded = (unsigned long long)s.count * s.stride;
        if (decoded != view.byteLength)
            return view_error(i, "decodes to " + std::to_string(decoded) +
                                     " bytes, not its byteLength of " +
                                     std::to_string(view.byteLength));
        // No stream holds more than 64 times its size (a vertex block's
        // header spends 2 bits on 16 bytes; an index takes a byte or more):
        // a larger claim is a file that would have ptr allocate for nothing.
        if (decoded > 128 * (unsigned long long)s.length + 256)
            return view_error(i, "claims " + std::to_string(decoded) + " bytes from a stream of " +
                                     std::to_string(s.length) + ", more than the codec holds");
        std::vector<unsigned char> &out = views[int(i)];
        out.resize(view.byteLength);
        const unsigned char *stream = source.data + s.offset;
        unsigned char *to = out.data();
        int failed = s.mode == "ATTRIBUTES"
                         ? meshopt_decodeVertexBuffer(to, s.count, s.stride, stream, s.length)
                     : s.mode == "TRIANGLES"
                         ? meshopt_decodeIndexBuffer(to, s.count, s.stride, stream, s.length)
                         : meshopt_decodeIndexSequence(to, s.count, s.stride, stream, s.length);
        if (failed)
            return view_error(i, "has a compressed stream that does not decode (truncated or "
                                 "corrupt)");
        unfilter(s, out.data());
    }
    return "";
}
