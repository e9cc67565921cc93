"""A second rasterizer to compare with: Mesa llvmpipe through OpenGL (moderngl, EGL, no display).

The same clip-space quads as ``render.rasterize_quads`` are drawn by the GPU pipeline:

- ``split``: the two triangles (0, 1, 2) and (0, 2, 3) with OpenGL's own perspective-correct
  interpolation of the corner attributes;
- ``mvc``: the same two triangles for coverage and depth, and in the fragment shader the
  perspective mean value coordinates of Hormann & Tarini 2004 (eq. 7 and 8 with the terms of
  eq. 10 and 11), evaluated from the quad's four clip-space corners read by
  ``gl_PrimitiveID`` from a shader storage buffer: with s~_i = X_i - p W_i,
  r_i = |s~_i|, A_i = s~_i x s~_{i+1}, D_i = s~_i . s~_{i+1},
  t_i = tan(alpha_i / 2) = A_i / (r_i r_{i+1} + D_i) for D_i > 0 else (r_i r_{i+1} - D_i) / A_i,
  mu_i = (t_{i-1} + t_i) / r_i, lambda_i = mu_i / sum_j mu_j.

Everything on the GPU side is float32 (positions, attributes, the 24-bit depth buffer), so
frames agree with the float64 NumPy ones to float32 precision, and pixel centres within
rounding of an edge may go to the other quad. Install: ``apt-get install libegl1
libgl1-mesa-dri libegl-mesa0`` and ``pip install moderngl``.
"""

from __future__ import annotations

import numpy as np

VERTEX_SHADER = """
#version 430
in vec4 in_clip;
in vec4 in_attrs;
out vec4 v_attrs;
void main() {
    gl_Position = in_clip;
    v_attrs = in_attrs;
}
"""

SPLIT_SHADER = """
#version 430
in vec4 v_attrs;
out vec4 out_frame;  // attributes in xyz, face + 1 in w
void main() {
    out_frame = vec4(v_attrs.xyz, float((gl_PrimitiveID >> 1) + 1));
}
"""

MVC_SHADER = """
#version 430
layout(std430, binding = 0) readonly buffer Quads { vec4 quad[]; };  // per quad: 4 clip corners, 4 attrs
uniform vec2 size;
out vec4 out_frame;  // attributes in xyz, face + 1 in w
float cross2(vec2 a, vec2 b) { return a.x * b.y - a.y * b.x; }
void main() {
    int q = gl_PrimitiveID >> 1;
    vec2 p = gl_FragCoord.xy * (2.0 / size) - 1.0;  // NDC of the pixel centre
    vec2 s[4];
    vec2 e[4];
    float r[4];
    for (int i = 0; i < 4; i++) {
        vec4 c = quad[8 * q + i], n = quad[8 * q + (i + 1) % 4];
        s[i] = c.xy - p * c.w;
        e[i] = (n.xy - c.xy) - p * (n.w - c.w);
        r[i] = length(s[i]);
    }
    float t[4];
    for (int i = 0; i < 4; i++) {
        int j = (i + 1) % 4;
        float A = r[i] <= r[j] ? cross2(s[i], e[i]) : cross2(s[j], e[i]);
        float D = dot(s[i], s[j]);
        float h = r[i] * r[j] + abs(D);
        t[i] = D > 0.0 ? A / h : h / A;
    }
    vec4 lam;
    for (int i = 0; i < 4; i++) lam[i] = (t[(i + 3) % 4] + t[i]) / r[i];
    lam /= lam.x + lam.y + lam.z + lam.w;
    vec4 a = lam.x * quad[8 * q + 4] + lam.y * quad[8 * q + 5] + lam.z * quad[8 * q + 6] + lam.w * quad[8 * q + 7];
    out_frame = vec4(a.xyz, float(q + 1));
}
"""

FRAGMENT_SHADERS = {"split": SPLIT_SHADER, "mvc": MVC_SHADER}
TRIANGLE_CORNERS = np.array([0, 1, 2, 0, 2, 3], dtype=np.int32)


def create_context():
    """A headless OpenGL 4.3+ context on EGL (Mesa llvmpipe without a GPU); raises if there is none."""
    import moderngl

    return moderngl.create_standalone_context(backend="egl", require=430)


class OpenGLQuads:
    """Clip-space quads uploaded once to an OpenGL context, drawn with ``draw`` and read with ``read``.

    clip : (Q, 4, 4) float, attrs : (Q, 4, K) float with K <= 3; width, height : int; method :
    ``"split"`` or ``"mvc"``; cull_backfaces : drop triangles wound clockwise in NDC, as
    ``rasterize_quads`` does.
    """

    def __init__(self, ctx, clip, attrs, width, height, method, cull_backfaces=False):
        clip = np.asarray(clip, dtype=np.float32)
        attrs = np.asarray(attrs, dtype=np.float32)
        if attrs.shape[2] > 3:
            raise ValueError(f"at most 3 attribute channels, got {attrs.shape[2]}")
        self.ctx, self.width, self.height, self.channels = ctx, width, height, attrs.shape[2]
        self.cull_backfaces = cull_backfaces
        padded = np.zeros(attrs.shape[:2] + (4,), np.float32)
        padded[..., : self.channels] = attrs
        n = clip.shape[0]
        vertices = np.concatenate([clip, padded], axis=2)  # (Q, 4, 8)
        indices = (4 * np.arange(n, dtype=np.int32)[:, None] + TRIANGLE_CORNERS).ravel()
        self.program = ctx.program(vertex_shader=VERTEX_SHADER, fragment_shader=FRAGMENT_SHADERS[method])
        self.buffers = [ctx.buffer(vertices.tobytes()), ctx.buffer(indices.tobytes())]
        if method == "mvc":
            self.program["size"].value = (width, height)
            self.buffers.append(ctx.buffer(np.concatenate([clip, padded], axis=1).tobytes()))  # (Q, 8, 4)
            self.buffers[2].bind_to_storage_buffer(0)
        # The mvc shader reads the attributes from the storage buffer: the vertices' are skipped.
        layout = (
            (self.buffers[0], "4f 4f", "in_clip", "in_attrs")
            if method == "split"
            else (self.buffers[0], "4f 16x", "in_clip")
        )
        self.vao = ctx.vertex_array(self.program, [layout], index_buffer=self.buffers[1])
        self.target = ctx.renderbuffer((width, height), 4, dtype="f4")
        self.depth = ctx.depth_renderbuffer((width, height))
        self.fbo = ctx.framebuffer(color_attachments=[self.target], depth_attachment=self.depth)

    def draw(self):
        """Clear and draw the frame (depth test "less"), then wait for it (glFinish)."""
        import moderngl

        self.fbo.use()
        self.ctx.enable(moderngl.DEPTH_TEST)
        if self.cull_backfaces:
            self.ctx.enable(moderngl.CULL_FACE)  # front faces: counter-clockwise, the default
        else:
            self.ctx.disable(moderngl.CULL_FACE)
        self.ctx.depth_func = "<"
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.vao.render(moderngl.TRIANGLES)
        self.ctx.finish()

    def read(self):
        """The drawn frame as NumPy arrays, row 0 at the top: face (H, W) int64 (-1 empty) and
        attrs (H, W, K) float64 (NaN empty)."""
        image = np.frombuffer(self.fbo.read(components=4, dtype="f4"), np.float32)
        image = image.reshape(self.height, self.width, 4)[::-1]
        face = image[..., 3].astype(np.int64) - 1
        attrs = image[..., : self.channels].astype(np.float64)
        attrs[face < 0] = np.nan
        return face, attrs

    def release(self):
        for resource in [self.vao, self.fbo, self.depth, self.target, self.program, *self.buffers]:
            resource.release()


def render_opengl(ctx, clip, attrs, width, height, method="split", cull_backfaces=False):
    """Draw once: face (H, W) int64 and attrs (H, W, K) float64, as ``OpenGLQuads.read``."""
    quads = OpenGLQuads(ctx, clip, attrs, width, height, method, cull_backfaces)
    try:
        quads.draw()
        return quads.read()
    finally:
        quads.release()
