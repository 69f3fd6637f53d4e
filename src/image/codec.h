#pragma once
/* The PNG and JPEG decoders, libpng and libjpeg-turbo, behind a C interface: both report
 * errors by longjmp, which must not cross C++ frames. Each reads an encoded file from
 * memory into the caller's buffer, so the caller decides where its pages are first touched
 * (on every thread: image.cpp). libjpeg-turbo decodes a photo in half stb_image's time and
 * libpng a PNG in two thirds (stb inflates the whole image into a second buffer first);
 * the decode is the one part of a command no thread shortens. */
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  uint32_t width, height;
  int alpha; /* 1: decodes to RGBA (an alpha channel or a transparent colour), 0: RGB */
  /* How the stored pixels are turned for viewing: EXIF's Orientation, 1 (as stored) to 8
   * (a phone's portrait photo is stored on its side, 6 or 8); 1 without the tag. */
  int orientation;
} codec_header;

/* Each reads the header into `h` and, when `out` is not NULL, decodes width x height x
 * (alpha ? 4 : 3) bytes, rows top to bottom, into it (a buffer sized from a header read
 * before). 1 on success; 0 on failure, with the decoder's reason in `why` (at most why_size
 * bytes, NUL-terminated). Truncated or damaged data is a failure, never a grey fill.
 * O(pixels); a JPEG's memory O(1) rows (baseline) or O(pixels) (progressive). */
int codec_png_read(const uint8_t* data, size_t size, codec_header* h, uint8_t* out, char* why, size_t why_size);
int codec_jpeg_read(const uint8_t* data, size_t size, codec_header* h, uint8_t* out, char* why, size_t why_size);

#ifdef __cplusplus
}
#endif
