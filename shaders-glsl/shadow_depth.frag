#version 460
// Depth only: a graphics pipeline needs a fragment stage, which has nothing to write here.

void main() {
}
