#version 450 core
// Depth pre-pass: no colour; the forward pass then shades each pixel once (GL_EQUAL).
// ALPHA_TEST 1: MASK materials discard their cut-out texels, so the forward pass, which
// shades only where its depth equals this pass's, never shades them either.
#include "material_common.glsl"
void main() { alpha_test(); }
