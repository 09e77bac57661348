#version 450 core
// Depth pre-pass: no colour; the forward pass then shades each pixel once (GL_EQUAL).
void main() {}
