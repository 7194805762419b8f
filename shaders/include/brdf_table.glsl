// Rows of the BRDF SH tables on the GPU (shine::passes::brdf_tables::GatherBrdf::gpu_data): F of Lambert
// (albedo 1, table 0) then F of GGX at each roughness node (tables 1..), each 90 rows of
// SH_COEFFS floats in the receiver frame (z = normal, omega_o in the xz half-plane), the
// shine_sh::brdf_table layout. Used by hvl_gather.comp, sh_filter.comp and proxy_shade.comp.
//
// Before the #include: SH_BANDS (sh.glsl) and a buffer instance `brdf` with `float f[]`.
#ifndef BRDF_TABLE_GLSL
#define BRDF_TABLE_GLSL

// shine_sh::brdf_table::THETA_SAMPLES
const int BRDF_TABLE_THETA_SAMPLES = 90;

// shine_sh::brdf_table::BrdfTable::lookup_f: linear interpolation between 1-degree rows
void brdf_table_row(int table, float theta_o, out float f[SH_COEFFS]) {
    float x = clamp(degrees(theta_o) - 0.5, 0.0, float(BRDF_TABLE_THETA_SAMPLES - 1));
    int i0 = int(floor(x));
    int i1 = min(i0 + 1, BRDF_TABLE_THETA_SAMPLES - 1);
    float t = x - float(i0);
    int base = table * BRDF_TABLE_THETA_SAMPLES * SH_COEFFS;
    SH_UNROLL for (int k = 0; k < SH_COEFFS; ++k) {
        f[k] = brdf.f[base + i0 * SH_COEFFS + k] * (1.0 - t) + brdf.f[base + i1 * SH_COEFFS + k] * t;
    }
}

// shine::passes::brdf_tables::GatherBrdf::glossy_f: the glossy row at `roughness`, blended linearly
// between the two tables around it (clamped to the nodes). nodes: roughness of the first table
// and the step between tables; tables: number of glossy tables.
void brdf_table_glossy_row(float roughness, vec2 nodes, uint tables, float theta_o, out float f[SH_COEFFS]) {
    float last = float(tables - 1u);
    float x = clamp((roughness - nodes.x) / nodes.y, 0.0, last);
    int k0 = min(int(floor(x)), int(last));
    int k1 = min(k0 + 1, int(last));
    float t = x - float(k0);
    float f0[SH_COEFFS];
    float f1[SH_COEFFS];
    brdf_table_row(1 + k0, theta_o, f0);
    brdf_table_row(1 + k1, theta_o, f1);
    SH_UNROLL for (int k = 0; k < SH_COEFFS; ++k) {
        f[k] = f0[k] * (1.0 - t) + f1[k] * t;
    }
}

#endif
