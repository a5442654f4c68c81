// Tree reduction of 9 RGB values per invocation over a workgroup of KAGE_SH_GROUP
// invocations: all 9 coefficients reduce together, so the whole sum costs log2(group) barriers.
#ifndef KAGE_SH_REDUCE_GLSL
#define KAGE_SH_REDUCE_GLSL

shared vec3 sh_sums[9][KAGE_SH_GROUP];

// Returns the workgroup's sums in invocation 0 (other invocations get partial values).
void sh_workgroup_sum(inout vec3 acc[9]) {
    uint lane = gl_LocalInvocationIndex;
    for (int i = 0; i < 9; ++i) sh_sums[i][lane] = acc[i];
    barrier();
    for (uint stride = KAGE_SH_GROUP / 2; stride > 0; stride /= 2) {
        if (lane < stride) {
            for (int i = 0; i < 9; ++i) sh_sums[i][lane] += sh_sums[i][lane + stride];
        }
        barrier();
    }
    for (int i = 0; i < 9; ++i) acc[i] = sh_sums[i][0];
}

#endif
