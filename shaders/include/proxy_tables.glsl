// The `tables` buffer of the proxy passes (shine::passes::proxy::ProxyTables::gpu_data), and
// sh.glsl's table hooks pointed at it. Include BEFORE sh.glsl, after defining SH_BANDS and
// PROXY_TABLES_BINDING. Layout (floats):
//   [0, 3 E n)            three alpha tables of E = PROXY_TABLE_ENTRIES rows of n = SH_BANDS
//   [3 E n, +1 + 2 K)     OL table: step, a[K], b[K], K = PROXY_OL_COUNT
//   then                  the tensor: N, N packed ijk (as floats, exact below 2^24), N values
//                         (shine_sh::glsl_tables::tensor_pairs of SH_BANDS)
#ifndef PROXY_TABLES_GLSL
#define PROXY_TABLES_GLSL

layout(set = 0, binding = PROXY_TABLES_BINDING, std430) readonly buffer Tables {
    float t[];
} tables;

// shine::passes::proxy::TABLE_ENTRIES
const int PROXY_TABLE_ENTRIES = 256;
// shine_sh::exp_log::OL_TABLE_SIZE
const int PROXY_OL_COUNT = 256;

#define SH_OL_BASE (3 * PROXY_TABLE_ENTRIES * SH_BANDS)
#define SH_OL_N PROXY_OL_COUNT
#define SH_OL_STEP_V tables.t[SH_OL_BASE]
#define SH_OL_A_AT(i) tables.t[SH_OL_BASE + 1 + (i)]
#define SH_OL_B_AT(i) tables.t[SH_OL_BASE + 1 + PROXY_OL_COUNT + (i)]
#define SH_TENSOR_BASE (SH_OL_BASE + 1 + 2 * PROXY_OL_COUNT)
#define SH_TENSOR_N int(tables.t[SH_TENSOR_BASE])
#define SH_TENSOR_IJK_AT(e) int(tables.t[SH_TENSOR_BASE + 1 + (e)])
#define SH_TENSOR_V_AT(e) tables.t[SH_TENSOR_BASE + 1 + SH_TENSOR_N + (e)]
#define SH_PRODUCT_ANY_BANDS

#endif
