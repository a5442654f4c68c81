#version 460
// Coverage, and coverage times the occluder's height above the receiver's plane.
layout(location = 0) in float height;
layout(location = 0) out vec2 covered;

void main() {
    covered = vec2(1.0, height);
}
