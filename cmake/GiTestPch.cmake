# gi_test_precompiled_headers(<target>): the headers nearly every test source includes,
# compiled once per test executable instead of once per source. GoogleTest's header alone
# costs ~3 s of every one of ~160 test sources, in the main build and again in the
# instrumented one (docs/reliability.md "Times"). Only third-party and standard headers: a
# change to a project header never rebuilds a precompiled header. A test source still
# includes what it uses (the precompiled header is an accelerator, not an include).
function(gi_test_precompiled_headers target)
  target_precompile_headers(${target} PRIVATE
    <gtest/gtest.h> <glm/glm.hpp> <algorithm> <cmath> <cstdio> <filesystem> <string> <vector>)
endfunction()
