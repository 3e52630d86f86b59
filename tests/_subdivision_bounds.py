"""Float32 error bounds of the geometry-image subdivision passes, shared by the GPU-against-twin tests of the
passes (tests/test_geometry_image_gpu.py, whose docstring derives them) and of the program
(tests/test_geometry_image_program.py). Unit roundoff u; gamma_c = c u / (1 - c u); each pass is a sum with
exact nonnegative weights summing to 1, bounded in its worst summation order by c roundings."""

U32, U64 = 2.0 ** -24, 2.0 ** -53
C_SPLIT, C_AVERAGE, C_LIMIT, C_TANGENT, C_PSS, C_PST = 3, 15, 10, 7, 10, 3


def gamma(c, u):
    return c * u / (1.0 - c * u)


def control_bounds(levels, M, u, upload):
    """Componentwise bounds on |computed g^k - exact g^k|, k = 0..levels, for an image of magnitude M (the upload
    rounds once when ``upload``; every split and average passes the error on unamplified and adds its own)."""
    e = [upload * u * M]
    for _ in range(levels):
        x = e[-1] + gamma(C_SPLIT, u) * (M + e[-1])
        e.append(x + gamma(C_AVERAGE, u) * (M + x))
    return e
