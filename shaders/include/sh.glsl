// Real spherical harmonics, GLSL twin of shine-sh (DESIGN §6): orthonormal, index l*l+l+m,
// with the Condon–Shortley phase. Y(1,-1) = -0.4886025 y, Y(1,0) = 0.4886025 z,
// Y(1,1) = -0.4886025 x.
//
// SH_BANDS (number of bands L, coefficients L*L) is a compile-time constant.
#ifndef SH_GLSL
#define SH_GLSL

#ifndef SH_BANDS
#error "define SH_BANDS (number of SH bands) before including sh.glsl"
#endif
#define SH_COEFFS (SH_BANDS * SH_BANDS)

const float SH_PI = 3.14159265358979323846;

// Evaluates every basis function at unit direction d.
// Recurrence on P~(l,m) = P(l,m)(z) / sin^m(theta) (a polynomial in z), with the azimuthal
// factor sin^m(theta) * (cos m phi, sin m phi) = Re/Im (x + i y)^m: no trigonometry and
// no factorials (K(l,m) is built as a running product).
void sh_basis(vec3 d, out float y[SH_COEFFS]) {
    float z = d.z;
    // c_m + i s_m = (x + i y)^m
    float c = 1.0;
    float s = 0.0;
    // P~(m,m) = (-1)^m (2m-1)!!
    float pmm = 1.0;
    for (int m = 0; m < SH_BANDS; ++m) {
        // K(l,m)^2 = (2l+1)/(4 pi) * (l-m)!/(l+m)!; at l = m the ratio is 1/(2m)!.
        float inv_fact = 1.0;
        for (int k = 1; k <= 2 * m; ++k) {
            inv_fact /= float(k);
        }
        float p_prev = 0.0;
        float p_cur = pmm;
        for (int l = m; l < SH_BANDS; ++l) {
            if (l > m) {
                // (l-m) P~(l,m) = (2l-1) z P~(l-1,m) - (l+m-1) P~(l-2,m)
                float p_next = (float(2 * l - 1) * z * p_cur - float(l + m - 1) * p_prev) / float(l - m);
                p_prev = p_cur;
                p_cur = p_next;
                // (l-m)!/(l+m)! from (l-1-m)!/(l-1+m)!: multiply by (l-m)/(l+m)
                inv_fact *= float(l - m) / float(l + m);
            }
            float k = sqrt(float(2 * l + 1) / (4.0 * SH_PI) * inv_fact);
            if (m == 0) {
                y[l * l + l] = k * p_cur;
            } else {
                float kk = sqrt(2.0) * k * p_cur;
                y[l * l + l + m] = kk * c;
                y[l * l + l - m] = kk * s;
            }
        }
        // advance (x + i y)^m and P~(m+1,m+1) = -(2m+1) P~(m,m)
        float c_next = c * d.x - s * d.y;
        s = c * d.y + s * d.x;
        c = c_next;
        pmm *= -float(2 * m + 1);
    }
}

#endif
