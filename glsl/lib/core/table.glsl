// Table textures: float data packed four per RGBA32F texel, SV_TABLE_WIDTH texels per row, read with
// texelFetch (no filtering, exact float32). Texel n sits at (n % W, n / W). The Python side is
// splinevis.gl.proxies.pack_rgba32f; the width is the same for every program (a test checks the two).
const int SV_TABLE_WIDTH = 8192;
// Rows of one texture of a split table (splinevis.gl.proxies.ROWS_PER_TEXTURE: 1 GiB per texture).

// Texture coordinates of texel n. A record of k texels starting at a multiple of k, k dividing
// SV_TABLE_WIDTH, lies in one row: fetch it at sv_table_address(first) + ivec2(q, 0).
ivec2 sv_table_address(int n) {
    return ivec2(n % SV_TABLE_WIDTH, n / SV_TABLE_WIDTH);
}

vec4 sv_table_texel(sampler2D table, int n) {
    return texelFetch(table, sv_table_address(n), 0);
}

// Float number n of the table (four per texel).
float sv_table_float(sampler2D table, int n) {
    int texel = n / 4;
    return sv_table_texel(table, texel)[n - 4 * texel];
}
