#include "render/picture_compose.hpp"

#include <cairo.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <vector>

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

// Margins: the title and the panel names above, the captions below, the colour bar and the
// scale bar on the right.
constexpr int kTop = 60, kBottom = 34, kRight = 170;
constexpr double kTitlePt = 16, kNamePt = 14, kTickPt = 12;

using Surface = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

Surface read_png(const fs::path& path) {
  Surface s(cairo_image_surface_create_from_png(path.c_str()), &cairo_surface_destroy);
  if (cairo_surface_status(s.get()) != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error("cannot read the render " + path.string() + ": " +
                             cairo_status_to_string(cairo_surface_status(s.get())));
  return s;
}

void set_rgb(cairo_t* cr, const Rgb& c) {
  cairo_set_source_rgb(cr, c[0], c[1], c[2]);
}

// Text with its anchor at (x, y): align 0 = left, 0.5 = centred, 1 = right; y is the baseline.
void text(cairo_t* cr, const std::string& s, double x, double y, double pt, double align,
          bool bold = false) {
  cairo_select_font_face(cr, "sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, pt);
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  cairo_move_to(cr, x - align * e.x_advance, y);
  cairo_show_text(cr, s.c_str());
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

// The colour bar: the scale's stops as a linear gradient (cairo interpolates in RGB between
// stops, as ColourScale does), five values, the axis label turned upright, the wound bed below.
void colour_bar(cairo_t* cr, double x0, int height, const ColourScale& scale) {
  const double top = kTop + 0.10 * height, bottom = kTop + 0.80 * height, w = 22;
  std::unique_ptr<cairo_pattern_t, decltype(&cairo_pattern_destroy)> g(
      cairo_pattern_create_linear(0, bottom, 0, top), &cairo_pattern_destroy);
  for (const auto& s : scale.stops)
    cairo_pattern_add_color_stop_rgb(g.get(), s[0], s[1], s[2], s[3]);
  cairo_rectangle(cr, x0, top, w, bottom - top);
  cairo_set_source(cr, g.get());
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_stroke(cr);
  for (int k = 0; k <= 4; ++k) {
    const double y = bottom - k / 4.0 * (bottom - top);
    cairo_move_to(cr, x0 + w, y);
    cairo_line_to(cr, x0 + w + 5, y);
    cairo_stroke(cr);
    text(cr, number(scale.min + k / 4.0 * (scale.max - scale.min)), x0 + w + 8, y + 4, kTickPt, 0);
  }
  cairo_save(cr);
  cairo_translate(cr, x0 + w + 78, 0.5 * (top + bottom));
  cairo_rotate(cr, -M_PI / 2);
  text(cr, scale.label, 0, 0, kTickPt, 0.5);
  cairo_restore(cr);
  const double swatch = kTop + 0.88 * height;
  cairo_rectangle(cr, x0, swatch, w, 18);
  set_rgb(cr, kWoundBed);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  text(cr, "wound bed", x0 + w + 8, swatch + 14, kTickPt, 0);
}

}  // namespace

PictureSize picture_size(int panels, int width, int height) {
  return {panels * width + kRight, height + kTop + kBottom};
}

ScaleBar scale_bar(double metres_per_pixel, int max_pixels) {
  ScaleBar bar{metres_per_pixel, 0, 0};
  if (!(metres_per_pixel > 0) || !std::isfinite(metres_per_pixel) || max_pixels <= 0) return bar;
  const double longest = metres_per_pixel * max_pixels;
  if (!std::isfinite(longest)) return bar;
  const double decade = std::pow(10.0, std::floor(std::log10(longest)));
  bar.length_m = decade / 10;  // log10's rounding may put `longest` just under `decade`
  for (const double m : {5.0, 2.0, 1.0})
    if (m * decade <= longest) {
      bar.length_m = m * decade;
      break;
    }
  bar.pixels = static_cast<int>(std::lround(bar.length_m / metres_per_pixel));
  return bar;
}

namespace {

// "20 mm", "0.5 mm", "2 m": a bar's length in the unit that reads best.
std::string length_label(double metres) {
  char buf[32];
  if (metres >= 1)
    std::snprintf(buf, sizeof buf, "%g m", metres);
  else if (metres >= 1e-3)
    std::snprintf(buf, sizeof buf, "%g mm", metres * 1e3);
  else
    std::snprintf(buf, sizeof buf, "%g µm", metres * 1e6);
  return buf;
}

// The scale bar below the colour bar and the wound bed's swatch: a black bar with end ticks, and
// below it its length "at the wound" (a perspective picture has one scale, at the target's depth).
void draw_scale_bar(cairo_t* cr, double x0, double y, const ScaleBar& bar) {
  if (bar.pixels <= 0) return;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 3);
  cairo_move_to(cr, x0, y);
  cairo_line_to(cr, x0 + bar.pixels, y);
  cairo_stroke(cr);
  cairo_set_line_width(cr, 1);
  for (const double x : {x0, x0 + bar.pixels}) {
    cairo_move_to(cr, x, y - 5);
    cairo_line_to(cr, x, y + 5);
    cairo_stroke(cr);
  }
  text(cr, length_label(bar.length_m) + " at the wound", x0, y + 18, kTickPt, 0);
}

}  // namespace

namespace {

// Into a temporary beside `out`, renamed when whole: no half-written picture. libpng's fast
// mode, not cairo's writer: 9 ms against 48 ms for the default picture, 35 % larger.
void write_png(cairo_surface_t* surface, const fs::path& out) {
  cairo_surface_flush(surface);
  const int w = cairo_image_surface_get_width(surface), h = cairo_image_surface_get_height(surface),
            stride = cairo_image_surface_get_stride(surface);
  const unsigned char* data = cairo_image_surface_get_data(surface);
  // cairo's RGB24: one native-endian 32-bit word per pixel, 0x00RRGGBB.
  std::vector<unsigned char> rgb(std::size_t(3) * w * h);
  for (int y = 0; y < h; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + std::ptrdiff_t(y) * stride);
    for (int x = 0; x < w; ++x) {
      unsigned char* px = &rgb[3 * (std::size_t(y) * w + x)];
      px[0] = (row[x] >> 16) & 0xff, px[1] = (row[x] >> 8) & 0xff, px[2] = row[x] & 0xff;
    }
  }
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(w);
  image.height = static_cast<png_uint_32>(h);
  image.format = PNG_FORMAT_RGB;
  image.flags = PNG_IMAGE_FLAG_FAST;
  const fs::path tmp = out.string() + ".part";
  if (!png_image_write_to_file(&image, tmp.c_str(), 0, rgb.data(), 3 * w, nullptr)) {
    const std::string why = image.message;
    png_image_free(&image);
    std::error_code ec;
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot write " + out.string() + ": " + why);
  }
  fs::rename(tmp, out);
}

Surface blank(int width, int height) {
  return {cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), &cairo_surface_destroy};
}

}  // namespace

void compose_picture(const fs::path& out, const std::vector<fs::path>& renders,
                     const PictureText& words, int width, int height, const ColourScale& scale) {
  const std::vector<std::string>& names = words.names;
  const int n = static_cast<int>(names.size());
  const PictureSize size = picture_size(n, width, height);
  const Surface canvas = blank(size.width, size.height);
  Context cr(cairo_create(canvas.get()), &cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1, 1, 1);
  cairo_paint(cr.get());
  int x = 0;
  for (const auto& path : renders) {
    const Surface render = read_png(path);
    const int w = cairo_image_surface_get_width(render.get());
    cairo_save(cr.get());
    cairo_rectangle(cr.get(), x, kTop, std::min(w, n * width - x), height);
    cairo_clip(cr.get());
    cairo_set_source_surface(cr.get(), render.get(), x, kTop);
    cairo_paint(cr.get());
    cairo_restore(cr.get());
    x += w;
  }
  cairo_set_source_rgb(cr.get(), 0, 0, 0);
  for (int i = 0; i < n; ++i)
    text(cr.get(), names[std::size_t(i)], (i + 0.5) * width, kTop - 8, kNamePt, 0.5);
  for (std::size_t i = 0; i < words.captions.size() && i < names.size(); ++i)
    text(cr.get(), words.captions[i], (double(i) + 0.5) * width, kTop + height + 22, kNamePt, 0.5,
         true);
  text(cr.get(), words.title, 0.5 * n * width, 24, kTitlePt, 0.5, true);
  colour_bar(cr.get(), n * width + 20, height, scale);
  draw_scale_bar(cr.get(), n * width + 20, kTop + height + 10, words.bar);
  write_png(canvas.get(), out);
}

}  // namespace conform::scenes
