#include "codec.h"

#include <setjmp.h>
#include <stdio.h>
#include <string.h>

#include <png.h>

#include <jpeglib.h>
/* jpeglib.h first: jerror.h's codes use its types. */
#include <jerror.h>

static void set_why(char* why, size_t why_size, const char* text) {
  if (why_size) snprintf(why, why_size, "%s", text);
}

/* ---- PNG (libpng) ---- */

typedef struct {
  const uint8_t* data;
  size_t size, at;
  char* why;
  size_t why_size;
} png_source;

static void png_read_memory(png_structp png, png_bytep out, size_t len) {
  png_source* s = (png_source*)png_get_io_ptr(png);
  if (len > s->size - s->at) png_error(png, "the file ends before the image does");
  memcpy(out, s->data + s->at, len);
  s->at += len;
}

static void png_on_error(png_structp png, png_const_charp msg) {
  png_source* s = (png_source*)png_get_error_ptr(png);
  set_why(s->why, s->why_size, msg);
  png_longjmp(png, 1);
}

/* Warnings (a known-bad sRGB profile, a damaged ancillary chunk that is dropped) leave the
 * pixels as they are: not the user's concern, and not printed. */
static void png_on_warning(png_structp png, png_const_charp msg) {
  (void)png;
  (void)msg;
}

/* Reads the header and sets the transforms to 8-bit RGB or RGBA: palette and grey expanded,
 * a transparent colour made alpha, 16 bits cut to their high 8 (as stb_image did). */
static void png_start(png_structp png, png_infop info, codec_header* h) {
  png_read_info(png, info);
  const int color = png_get_color_type(png, info);
  const int depth = png_get_bit_depth(png, info);
  const int transparent_colour = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (color == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
  if (transparent_colour) png_set_tRNS_to_alpha(png);
  if (depth == 16) png_set_strip_16(png);
  if (color == PNG_COLOR_TYPE_GRAY || color == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
  h->width = png_get_image_width(png, info);
  h->height = png_get_image_height(png, info);
  h->alpha = (color & PNG_COLOR_MASK_ALPHA) != 0 || transparent_colour;
  h->orientation = 1;
}

int codec_png_read(const uint8_t* data, size_t size, codec_header* h, uint8_t* out, char* why, size_t why_size) {
  png_source src = {data, size, 0, why, why_size};
  if (size < 8 || png_sig_cmp(data, 0, 8) != 0) {
    set_why(why, why_size, "not a PNG signature");
    return 0;
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, png_on_error, png_on_warning);
  if (!png) {
    set_why(why, why_size, "out of memory");
    return 0;
  }
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, NULL, NULL);
    set_why(why, why_size, "out of memory");
    return 0;
  }
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, NULL);
    return 0;
  }
  png_set_read_fn(png, &src, png_read_memory);
  png_start(png, info, h);
  if (out) {
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    const size_t stride = (size_t)h->width * (h->alpha ? 4u : 3u);
    if (png_get_rowbytes(png, info) != stride) png_error(png, "unexpected row layout");
    /* An interlaced image's passes each fill in the rows the previous ones left. */
    for (int p = 0; p < passes; ++p)
      for (uint32_t y = 0; y < h->height; ++y) png_read_row(png, out + (size_t)y * stride, NULL);
    /* The chunks after the pixels (text, time) are not read: a file cut after its last
     * pixel row still gives the whole picture. */
  }
  png_destroy_read_struct(&png, &info, NULL);
  return 1;
}


/* ---- JPEG (libjpeg-turbo) ---- */

typedef struct {
  struct jpeg_error_mgr mgr;
  jmp_buf jump;
  char* why;
  size_t why_size;
} jpeg_failure;

static void jpeg_on_error(j_common_ptr ci) {
  jpeg_failure* f = (jpeg_failure*)ci->err;
  char text[JMSG_LENGTH_MAX];
  (*ci->err->format_message)(ci, text);
  set_why(f->why, f->why_size, text);
  longjmp(f->jump, 1);
}

/* libjpeg goes on past damage with a warning and fills the rest grey; a drawing of that
 * grey would waste the user's hour, so damage is an error. Warnings about harmless oddities
 * (stray bytes between segments, unknown markers' versions) are not. */
static void jpeg_on_message(j_common_ptr ci, int level) {
  if (level >= 0) return; /* trace messages */
  switch (ci->err->msg_code) {
    case JWRN_JPEG_EOF:
    case JWRN_HIT_MARKER:
    case JWRN_HUFF_BAD_CODE:
    case JWRN_ARITH_BAD_CODE:
    case JWRN_MUST_RESYNC:
    case JWRN_NOT_SEQUENTIAL:
    case JWRN_BOGUS_PROGRESSION:
      jpeg_on_error(ci);
      break;
    default:
      break;
  }
}

/* A progressive file may hold any number of scans, each a pass over the whole image: a
 * small hostile file could take hours. TurboJPEG's own limit (TJFLAG_LIMITSCANS). */
enum { kMaxScans = 500 };

static void jpeg_on_progress(j_common_ptr ci) {
  j_decompress_ptr d = (j_decompress_ptr)ci;
  if (d->input_scan_number > kMaxScans) {
    jpeg_failure* f = (jpeg_failure*)ci->err;
    set_why(f->why, f->why_size, "more than 500 scans");
    longjmp(f->jump, 1);
  }
}

/* EXIF's Orientation tag (0x0112) in an APP1 segment ("Exif\0\0", then a TIFF header and its
 * first directory); 1 when absent or out of its range 1-8. Every read is bounds-checked. */
static int exif_orientation(const uint8_t* d, size_t n) {
  if (n < 14 || memcmp(d, "Exif\0\0", 6) != 0) return 1;
  d += 6, n -= 6;
  const int little = d[0] == 'I' && d[1] == 'I';
  if (!little && !(d[0] == 'M' && d[1] == 'M')) return 1;
#define EXIF_U16(p) (little ? (unsigned)((p)[0] | (p)[1] << 8) : (unsigned)((p)[0] << 8 | (p)[1]))
#define EXIF_U32(p) (little ? ((uint32_t)(p)[0] | (uint32_t)(p)[1] << 8 | (uint32_t)(p)[2] << 16 | (uint32_t)(p)[3] << 24) \
                            : ((uint32_t)(p)[0] << 24 | (uint32_t)(p)[1] << 16 | (uint32_t)(p)[2] << 8 | (uint32_t)(p)[3]))
  int found = 1;
  const uint32_t ifd = EXIF_U32(d + 4);
  if (EXIF_U16(d + 2) == 42 && ifd <= n - 2) {
    const unsigned entries = EXIF_U16(d + ifd);
    for (unsigned i = 0; i < entries; ++i) {
      const size_t at = ifd + 2 + (size_t)i * 12;
      if (at + 12 > n) break;
      if (EXIF_U16(d + at) == 0x0112 && EXIF_U16(d + at + 2) == 3) { /* a SHORT */
        const unsigned v = EXIF_U16(d + at + 8);
        if (v >= 1 && v <= 8) found = (int)v;
        break;
      }
    }
  }
#undef EXIF_U16
#undef EXIF_U32
  return found;
}

/* Adobe's CMYK, stored inverted: each colour scaled by the black, as stb_image did. */
static uint8_t times_black(unsigned c, unsigned k) {
  const unsigned t = c * k + 128u;
  return (uint8_t)((t + (t >> 8)) >> 8);
}

int codec_jpeg_read(const uint8_t* data, size_t size, codec_header* h, uint8_t* out, char* why, size_t why_size) {
  struct jpeg_decompress_struct ci;
  jpeg_failure fail;
  struct jpeg_progress_mgr progress;
  memset(&ci, 0, sizeof ci);
  ci.err = jpeg_std_error(&fail.mgr);
  fail.mgr.error_exit = jpeg_on_error;
  fail.mgr.emit_message = jpeg_on_message;
  fail.why = why;
  fail.why_size = why_size;
  progress.progress_monitor = jpeg_on_progress;
  if (setjmp(fail.jump)) {
    jpeg_destroy_decompress(&ci);
    return 0;
  }
  jpeg_create_decompress(&ci);
  ci.progress = &progress;
  jpeg_mem_src(&ci, data, (unsigned long)size);
  jpeg_save_markers(&ci, JPEG_APP0 + 1, 0xFFFF);
  jpeg_read_header(&ci, TRUE);
  const int cmyk = ci.jpeg_color_space == JCS_CMYK || ci.jpeg_color_space == JCS_YCCK;
  ci.out_color_space = cmyk ? JCS_CMYK : JCS_RGB;
  h->width = ci.image_width;
  h->height = ci.image_height;
  h->alpha = 0;
  h->orientation = 1;
  for (jpeg_saved_marker_ptr m = ci.marker_list; m; m = m->next)
    if (m->marker == JPEG_APP0 + 1 && (h->orientation = exif_orientation(m->data, m->data_length)) != 1) break;
  if (out) {
    jpeg_start_decompress(&ci);
    if (ci.output_width != h->width || ci.output_height != h->height || ci.output_components != (cmyk ? 4 : 3))
      ERREXIT(&ci, JERR_BAD_DCTSIZE);
    const size_t stride = (size_t)h->width * 3u;
    /* CMYK rows pass through a row of the decoder's own memory (freed with it). */
    JSAMPARRAY cmyk_row = cmyk ? (*ci.mem->alloc_sarray)((j_common_ptr)&ci, JPOOL_IMAGE, h->width * 4u, 1) : NULL;
    while (ci.output_scanline < ci.output_height) {
      uint8_t* row = out + (size_t)ci.output_scanline * stride;
      if (!cmyk) {
        JSAMPROW rows[1] = {row};
        jpeg_read_scanlines(&ci, rows, 1);
        continue;
      }
      jpeg_read_scanlines(&ci, cmyk_row, 1);
      const uint8_t* q = cmyk_row[0];
      for (uint32_t x = 0; x < h->width; ++x, q += 4)
        for (int c = 0; c < 3; ++c) row[x * 3 + (uint32_t)c] = times_black(q[c], q[3]);
    }
    /* Not jpeg_finish_decompress: what follows the last row (the end marker) is not
     * needed, as for a PNG. */
  }
  jpeg_destroy_decompress(&ci);
  return 1;
}
