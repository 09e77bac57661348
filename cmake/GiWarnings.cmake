# Warnings and sanitizers for project code, through INTERFACE targets (never applied to
# third-party headers, which are included as SYSTEM).
add_library(gi_warnings INTERFACE)
target_compile_options(gi_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual
  -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough
  # (-Wnull-dereference is left out: GCC 12 raises false positives inside libstdc++ at -O2.)
  # Designated initializers that leave members at their defaults are the point of plain
  # component structs; GCC 12 would warn on every one.
  -Wno-missing-field-initializers)
if(GI_WERROR)
  target_compile_options(gi_warnings INTERFACE -Werror)
endif()

add_library(gi_sanitize INTERFACE)
if(GI_SANITIZE)
  target_compile_options(gi_sanitize INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                         -fno-sanitize-recover=undefined)
  target_link_options(gi_sanitize INTERFACE -fsanitize=address,undefined)
endif()
