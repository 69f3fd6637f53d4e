#pragma once
// An uploaded photo, accepted only as the CLI would: a known image format by its first
// bytes, and decoded with the same checks as `--max-pixels` (from the header, before
// decoding). A reduced copy is kept for previews while a control is being dragged.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace stipplot::serve {

struct Photo {
  std::string name;        // in the working folder: photo.jpg / photo.png / ...
  std::string draft_name;  // photo-draft.tga, at most the draft's pixels
  std::string original_name;
  int width = 0, height = 0, draft_width = 0, draft_height = 0;
  nlohmann::json to_json() const;
};

// Throws RequestError: 415 for what is not an image (or a broken one), 413 for more
// pixels than `max_pixels`. O(pixels).
Photo accept_photo(const std::string& bytes, const std::filesystem::path& workdir, uint64_t max_pixels,
                   uint64_t draft_pixels);

}  // namespace stipplot::serve
