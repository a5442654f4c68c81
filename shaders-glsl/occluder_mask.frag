#version 460
// Coverage, and coverage times the occluder's height above the mask's plane (the receiver
// writes zeros, which the cleared mask holds already).
layout(location = 0) in flat float weight;
layout(location = 1) in float height;
layout(location = 0) out vec4 covered;

void main() {
    covered = vec4(weight, weight * height, 0.0, 0.0);
}
