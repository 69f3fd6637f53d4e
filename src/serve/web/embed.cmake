# Writes the studio's page and script into a C++ source as raw string literals, so the
# binary serves them with no files beside it (no build step, no CDN).
file(READ ${HTML} page)
file(READ ${JS} script)
foreach(text page script)
  string(FIND "${${text}}" ")STUDIO\"" bad)
  if(NOT bad EQUAL -1)
    message(FATAL_ERROR "the studio's ${text} contains the literal's delimiter )STUDIO\"")
  endif()
endforeach()
file(WRITE ${OUT}.tmp "// Generated from src/serve/web by embed.cmake; do not edit.\n"
  "namespace stipplot::serve {\nextern const char* const kStudioPage;\nextern const char* const kStudioScript;\n"
  "const char* const kStudioPage = R\"STUDIO(${page})STUDIO\";\n"
  "const char* const kStudioScript = R\"STUDIO(${script})STUDIO\";\n}\n")
file(COPY_FILE ${OUT}.tmp ${OUT} ONLY_IF_DIFFERENT)
