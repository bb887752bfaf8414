// imageio.cpp -- OpenImageIO behind a C header (imageio.h).  Nothing else
// in the coordinator is C++, and no C++ exception crosses into C.
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>

extern "C" {
#include "imageio.h"
}

using namespace OIIO;

extern "C" int iio_write(const char *path, const void *pixels, iio_type type, uint32_t width,
                         uint32_t height, fr_error *err)
{
    try {
        TypeDesc td = type == IIO_U8 ? TypeDesc::UINT8 : type == IIO_U16 ? TypeDesc::UINT16 : TypeDesc::FLOAT;
        std::unique_ptr<ImageOutput> out = ImageOutput::create(path);
        if (!out)
            return fr_fail(err, "%s: no image writer for this extension: %s", path, OIIO::geterror().c_str());
        ImageSpec spec((int)width, (int)height, 3, td);
        spec.attribute("oiio:ColorSpace", type == IIO_F32 ? "linear" : "sRGB");
        spec.attribute("Software", "franja");
        if (!out->open(path, spec))
            return fr_fail(err, "%s: %s", path, out->geterror().c_str());
        if (!out->write_image(td, pixels)) {
            std::string e = out->geterror();
            out->close();
            return fr_fail(err, "%s: %s", path, e.c_str());
        }
        if (!out->close())
            return fr_fail(err, "%s: %s", path, out->geterror().c_str());
        return 0;
    } catch (const std::exception &e) {
        return fr_fail(err, "%s: %s", path, e.what());
    }
}

extern "C" int iio_can_write(const char *path)
{
    try {
        std::unique_ptr<ImageOutput> out = ImageOutput::create(path);
        return out != nullptr;
    } catch (...) {
        return 0;
    }
}
