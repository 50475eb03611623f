/* EXT_meshopt_compression, for gltf_doc.cpp: buffer views whose data is
 * compressed by meshoptimizer, decoded with the library made for it. */
#ifndef PTR_GLTF_MESHOPT_H
#define PTR_GLTF_MESHOPT_H

#ifndef __cplusplus
#error "gltf_meshopt.h is for gltf_doc.cpp"
#endif

#include <map>
#include <string>
#include <vector>

#include <tiny_gltf.h>

extern const char *const meshopt_extension; /* "EXT_meshopt_compression" */

/* A buffer's bytes: tinygltf's copy, or a mapped .glb's BIN chunk. */
struct GltfBytes {
    const unsigned char *data;
    size_t size;
};

/* Decodes every compressed buffer view of the model (buffers: each buffer's
 * bytes) into views[index], of the view's byteLength. Returns "" or what is
 * wrong, naming the extension. */
std::string meshopt_decode(const tinygltf::Model &model, const std::vector<GltfBytes> &buffers,
                           std::map<int, std::vector<unsigned char>> &views);

#endif /* PTR_GLTF_MESHOPT_H */
