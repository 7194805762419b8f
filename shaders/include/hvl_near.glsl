// HVL's traced near field (src/passes/hvl/near.rs): how the light of a sender point is split
// between the HVL gather and the near-field pass, shared by hvl_gather.comp and hvl_near.comp.
#ifndef HVL_NEAR_GLSL
#define HVL_NEAR_GLSL

// shine_sh::hvl::far_weight: the gather's share of a sender point at `distance` when the near
// field within `range` (R) is traced, smoothstep((d - R) / R); 1 when range is 0. The near
// field's pass takes 1 minus it.
float hvl_far_weight(float distance, float range) {
    return range > 0.0 ? smoothstep(0.0, 1.0, (distance - range) / range) : 1.0;
}

#endif // HVL_NEAR_GLSL
