// tinygltf's own load of a glTF file and nothing else, as ptr's glTF shim
// calls it (images skipped): the baseline ptr's import is measured against
// (bench/import.sh).
#include <tiny_gltf.h>

#include <cstdio>
#include <cstring>

static bool skip_image(tinygltf::Image *, const int, std::string *, std::string *, int, int,
                       const unsigned char *, int, void *)
{
    return true;
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        std::fprintf(stderr, "usage: tinygltf_load FILE.gltf|FILE.glb\n");
        return 2;
    }
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(skip_image, nullptr);
    std::string error, warning;
    const size_t length = std::strlen(argv[1]);
    const bool binary = length > 4 && std::strcmp(argv[1] + length - 4, ".glb") == 0;
    bool ok = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, argv[1])
                     : loader.LoadASCIIFromFile(&model, &error, &warning, argv[1]);
    std::printf("%s: %zu nodes%s%s\n", argv[1], model.nodes.size(), ok ? "" : ": ", error.c_str());
    return ok ? 0 : 1;
}
