/* imageio.cpp -- OpenImageIO behind a C header (imageio.h).  Nothing else
 * in the coordinator is C++, and no C++ exception crosses into C. */
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

extern "C" {
#include "imageio.h"
}

using namespace OIIO;

// Encodes into an anonymous memory file: OpenImageIO's writers open files
// by name, and several of them (PNG, BMP, TGA) do not report a failed write
// while libjpeg's exits the process; in memory no write can fail for lack
// of disk space, and the caller then writes the bytes with every write
// checked.  The writer is chosen by the extension of `name`, and opens the
// memory file through /proc/self/fd.
extern "C" int iio_encode_with(const char *name, const void *pixels, iio_type type, uint32_t width, uint32_t height,
                               const iio_options *o, unsigned char **data, size_t *len, fr_error *err)
{
    *data = nullptr;
    *len = 0;
    int fd = memfd_create("franja-image", MFD_CLOEXEC);
    if (fd < 0)
        return fr_fail(err, "%s: cannot make an in-memory file to encode into: %s", name, strerror(errno));
    char mem[64];
    snprintf(mem, sizeof mem, "/proc/self/fd/%d", fd);
    int rc = 0;
    try {
        if (type == IIO_F16)
            return close(fd), fr_fail(err, "%s: half-float pixels cannot be encoded (give floats)", name);
        TypeDesc td = type == IIO_U8 ? TypeDesc::UINT8 : type == IIO_U16 ? TypeDesc::UINT16 : TypeDesc::FLOAT;
        std::unique_ptr<ImageOutput> out = ImageOutput::create(name);
        if (!out) {
            rc = fr_fail(err, "%s: no image writer for this extension: %s", name, OIIO::geterror().c_str());
        } else {
            // Half floats are stored from the float pixels (OpenImageIO converts).
            int nch = o && o->channels && type == IIO_F32 ? (int)o->channels : 3;
            ImageSpec spec((int)width, (int)height, nch, o && o->half && type == IIO_F32 ? TypeDesc::HALF : td);
            if (nch != 3 && o->channel_names) {
                // Named channels (render passes): "Layer.Pass.Channel", the
                // first four the beauty's RGBA.
                spec.channelnames.clear();
                for (int c = 0; c < nch; c++)
                    spec.channelnames.emplace_back(o->channel_names[c]);
                spec.alpha_channel = nch >= 4 ? 3 : -1;
            }
            spec.attribute("oiio:ColorSpace", type == IIO_F32 ? "linear" : "sRGB");
            spec.attribute("Software", "franja");
            if (o && o->compression)
                spec.attribute("compression", o->compression);
            if (o && o->quality > 0)
                spec.attribute("compression", std::string("jpeg:") + std::to_string(o->quality));
            for (const char *const *a = o ? o->attrs : nullptr; a && a[0] && a[1]; a += 2)
                spec.attribute(a[0], a[1]);
            if (!out->open(mem, spec)) {
                rc = fr_fail(err, "%s: encoding: %s", name, out->geterror().c_str());
            } else if (!out->write_image(td, pixels)) {
                std::string e = out->geterror();
                out->close();
                rc = fr_fail(err, "%s: encoding: %s", name, e.c_str());
            } else if (!out->close()) {
                rc = fr_fail(err, "%s: encoding: %s", name, out->geterror().c_str());
            }
        }
    } catch (const std::exception &e) {
        rc = fr_fail(err, "%s: encoding: %s", name, e.what());
    }
    struct stat st;
    if (rc == 0 && fstat(fd, &st))
        rc = fr_fail(err, "%s: encoding: %s", name, strerror(errno));
    if (rc == 0 && st.st_size <= 0)
        rc = fr_fail(err, "%s: encoding: the image writer wrote nothing", name);
    unsigned char *buf = nullptr;
    if (rc == 0 && !(buf = (unsigned char *)malloc((size_t)st.st_size)))
        rc = fr_fail(err, "%s: out of memory for the encoded image (%lld bytes)", name, (long long)st.st_size);
    for (size_t got = 0; rc == 0 && got < (size_t)st.st_size;) {
        ssize_t k = pread(fd, buf + got, (size_t)st.st_size - got, (off_t)got);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            rc = fr_fail(err, "%s: encoding: reading back: %s", name, k < 0 ? strerror(errno) : "short file");
        else
            got += (size_t)k;
    }
    close(fd);
    if (rc) {
        free(buf);
        return rc;
    }
    *data = buf;
    *len = (size_t)st.st_size;
    return 0;
}

// Reads the first image of an opened input into *pixels (see iio_read).
static int read_open(ImageInput *in, const char *name, const iio_dest *dest, void **pixels, iio_type *type,
                     uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err)
{
    const ImageSpec &spec = in->spec();
    uint64_t n = (uint64_t)spec.width * (uint64_t)spec.height * (uint64_t)spec.nchannels;
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth > 1 || n > (1u << 29))
        return fr_fail(err, "%s: %d x %d x %d pixels, %d channels: not a 2D image of at most 2^29 values", name,
                       spec.width, spec.height, spec.depth, spec.nchannels);
    // The file's own precision: 8-bit, 16-bit and half stay so, the rest
    // (float, double, 32-bit integers) becomes float.
    TypeDesc td = TypeDesc::FLOAT;
    iio_type t = IIO_F32;
    size_t size = 4;
    if (spec.format.basetype == TypeDesc::UINT8) {
        td = TypeDesc::UINT8, t = IIO_U8, size = 1;
    } else if (spec.format.basetype == TypeDesc::UINT16) {
        td = TypeDesc::UINT16, t = IIO_U16, size = 2;
    } else if (spec.format.basetype == TypeDesc::HALF) {
        td = TypeDesc::HALF, t = IIO_F16, size = 2;
    }
    // The caller's place (only the channels it keeps), else malloc'd.
    uint32_t keep = (uint32_t)spec.nchannels;
    void *px = dest && dest->at ? dest->at(dest, (uint32_t)spec.width, (uint32_t)spec.height, keep, t, &keep)
                                : nullptr;
    bool own = !px;
    if (own) {
        keep = (uint32_t)spec.nchannels;
        px = malloc(n * size);
    } else if (keep < 1 || keep > (uint32_t)spec.nchannels) {
        return fr_fail(err, "%s: asked to keep %u of %d channels", name, keep, spec.nchannels);
    }
    if (!px)
        return fr_fail(err, "%s: out of memory for %llu values", name, (unsigned long long)n);
    bool ok = true;
    try {
        if (spec.tile_width > 0) {
            ok = in->read_image(0, 0, 0, (int)keep, td, px);
        } else {
            // Scanline files a few MiB of rows at a time: read_image
            // would decode the whole image into a buffer of its own
            // first, a second copy.
            size_t row = (size_t)spec.width * keep * size;
            int chunk = (int)std::max<size_t>(1, ((size_t)4 << 20) / row);
            for (int y = 0; y < spec.height && ok; y += chunk) {
                int end = std::min(spec.height, y + chunk);
                ok = in->read_scanlines(0, 0, spec.y + y, spec.y + end, spec.z, 0, (int)keep, td,
                                        (char *)px + (size_t)y * row);
            }
        }
    } catch (...) {
        if (own)
            free(px);
        throw;
    }
    if (!ok) {
        if (own)
            free(px);
        return fr_fail(err, "%s: %s", name, in->geterror().c_str());
    }
    *pixels = px;
    *type = t;
    *width = (uint32_t)spec.width;
    *height = (uint32_t)spec.height;
    *channels = keep;
    return 0;
}

// Files are read by the caller (through its confinement rule) and decoded
// here from memory: OpenImageIO never opens a name of the scene's.  The
// reader is chosen by the extension of `name`; a reader without I/O proxy
// support (older OpenImageIO) reads a private memory file through
// /proc/self/fd instead.
extern "C" int iio_read(const char *name, const void *data, size_t len, const iio_dest *dest, void **pixels,
                        iio_type *type, uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err)
{
    *pixels = nullptr;
    const char *dot = strrchr(name, '.'), *slash = strrchr(name, '/');
    if (!dot || (slash && dot < slash) || !dot[1] || strlen(dot) > 16)
        return fr_fail(err, "%s: no extension to choose an image reader by", name);
    std::string ext(dot + 1);
    int fd = -1;
    try {
        std::unique_ptr<ImageInput> in = ImageInput::create(ext);
        if (!in)
            return fr_fail(err, "%s: no image reader for this extension", name);
        Filesystem::IOMemReader mem(const_cast<void *>(data), len); // OIIO 2.2 takes a non-const pointer; it only reads
        ImageSpec spec;
        bool ok;
        if (in->supports("ioproxy") && in->set_ioproxy(&mem)) {
            ok = in->open(std::string("image.") + ext, spec);
        } else {
            fd = memfd_create("franja-texture", MFD_CLOEXEC);
            if (fd < 0)
                return fr_fail(err, "%s: cannot make an in-memory file to decode from: %s", name, strerror(errno));
            const char *p = (const char *)data;
            for (size_t left = len; left > 0;) {
                ssize_t k = write(fd, p, left);
                if (k <= 0) {
                    if (k < 0 && errno == EINTR)
                        continue;
                    close(fd);
                    return fr_fail(err, "%s: cannot fill an in-memory file: %s", name, strerror(errno));
                }
                p += k;
                left -= (size_t)k;
            }
            char mf[64];
            snprintf(mf, sizeof mf, "/proc/self/fd/%d", fd);
            ok = in->open(mf, spec);
        }
        if (!ok)
            (void)in->geterror(); // the reader's words may quote the bytes: cleared, not shown
        int rc = ok ? read_open(in.get(), name, dest, pixels, type, width, height, channels, err)
                    : fr_fail(err, "%s: not a readable %s image", name, ext.c_str());
        in.reset();
        if (fd >= 0)
            close(fd);
        return rc;
    } catch (const std::exception &e) {
        free(*pixels);
        *pixels = nullptr;
        if (fd >= 0)
            close(fd);
        return fr_fail(err, "%s: %s", name, e.what());
    }
}

extern "C" int iio_read_mem(const void *data, size_t len, const char *mime, const iio_dest *dest, void **pixels,
                            iio_type *type, uint32_t *width, uint32_t *height, uint32_t *channels, fr_error *err)
{
    *pixels = nullptr;
    // The format by its signature first (a MIME type may be wrong), then
    // by the MIME type.
    const unsigned char *b = (const unsigned char *)data;
    const char *name = nullptr;
    if (len >= 8 && !memcmp(b, "\x89PNG\r\n\x1a\n", 8))
        name = "embedded.png";
    else if (len >= 3 && b[0] == 0xff && b[1] == 0xd8 && b[2] == 0xff)
        name = "embedded.jpg";
    else if (mime && !strcmp(mime, "image/png"))
        name = "embedded.png";
    else if (mime && !strcmp(mime, "image/jpeg"))
        name = "embedded.jpg";
    if (!name)
        return fr_fail(err, "embedded image: neither PNG nor JPEG (MIME type '%s')", mime ? mime : "");
    try {
        Filesystem::IOMemReader mem(const_cast<void *>(data), len); // OIIO 2.2 takes a non-const pointer; it only reads
        std::unique_ptr<ImageInput> in = ImageInput::open(name, nullptr, &mem);
        if (!in)
            return fr_fail(err, "embedded %s image: %s", name + 9, OIIO::geterror().c_str());
        return read_open(in.get(), "embedded image", dest, pixels, type, width, height, channels, err);
    } catch (const std::exception &e) {
        free(*pixels);
        *pixels = nullptr;
        return fr_fail(err, "embedded image: %s", e.what());
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
