#pragma once
// What a command no longer needs but would spend time freeing: a plan or drawing of a
// million strokes is a million heap blocks, and freeing them one by one took a quarter
// of a second of a 1M-dot export; the process's exit returns all its memory at once.
// Only for what lives until the command ends anyway. The values stay reachable from a
// global, so leak checkers (the sanitizer build) do not report them.
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace stipplot {

template <class T>
void keep_until_exit(T&& value) {
  // Never destroyed: a destructor at exit would free the blocks after all.
  static auto* kept = new std::vector<std::shared_ptr<void>>();
  kept->push_back(std::make_shared<std::decay_t<T>>(std::forward<T>(value)));
}

}  // namespace stipplot
