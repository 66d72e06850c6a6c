// kiosk_www.hpp - the page's files, compiled in from src/kiosk/www/ at build
// time (cmake/embed_www.cmake): the server answers exactly these paths.
#pragma once

#include <cstddef>
#include <string>

namespace gs::kiosk {

struct WwwFile {
    const char *path;  // "/index.html"
    const char *type;  // its Content-Type
    const unsigned char *data;
    size_t size;
};

// nullptr unless path is one of the files
const WwwFile *www_find(const std::string &path);

}  // namespace gs::kiosk
