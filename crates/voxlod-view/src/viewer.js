// voxlod view: a small WebGL2 renderer for voxlod's .glb files (crates/voxlod-view/src/lib.rs
// says why it is ours rather than three.js). It draws one model at a time:
//  - an MSFT_lod chain, choosing the level by screen coverage (the MSFT_screencoverage entries,
//    scaled from the file's viewport height to the canvas's: voxlod select's pixel-size rule);
//  - layered shells (accessors order±x±y±z), blended back to front with the order of the view
//    direction's octant, and only while the filter radius on screen is at most 0.45 px
//    (BENCHMARKS.md); closer, the single surface (the layer nearest isodensity 0.5), opaque;
//  - a chain of layered levels (voxlod layers --lod: accessors "level K order±x±y±z"): the
//    coarsest level whose filter radius on screen is at most 0.45 px, drawn as above; closer
//    than level 0 allows, level 0's single surface;
//  - the LOD0, LOD1, … node layout (voxlod's --layout lod-nodes) as a chain, with the coverages
//    voxlod's writer gives an MSFT_lod chain by default (coverageByTriangles);
//  - any other glTF: triangles shaded, lines as thick screen-space quads (at least EDGE_PX, or
//    their _WIDTH in object units on screen), points as squares.
// Triangles are drawn with their materials (MATERIAL_FS: base colour factor × texture × vertex
// colour, alpha mask and blend, normal map, emissive); images decode asynchronously, a white
// stand-in until then; what cannot be shown is named in the overlay.
// The camera is set by the URL hash (#camera=DISTANCE,DX,DY,DZ&model=I, DX.. pointing from the
// object's centre to the eye) or window.voxlodView.setCamera(distance, [dx, dy, dz]).
// The state drawn is in document.title and in a colour patch at the top left (level or octant;
// a layered chain shows its level in a second patch below).
"use strict";
(function () {
  const FOV = Math.PI / 4;
  const EDGE_PX = 3.0;
  const POINT_PX = 7.0;
  const RADIUS_LIMIT_PX = 0.45;
  const PALETTE = [
    [230, 25, 75], [60, 180, 75], [0, 130, 200], [245, 130, 48],
    [145, 30, 180], [70, 240, 240], [240, 50, 230], [210, 245, 60],
  ];
  const COMPONENTS = {
    5120: [Int8Array, 1], 5121: [Uint8Array, 1], 5122: [Int16Array, 2],
    5123: [Uint16Array, 2], 5125: [Uint32Array, 4], 5126: [Float32Array, 4],
  };
  const SIZES = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };
  // The page's grey for triangles without a material, linear (sRGB 0.75, 0.76, 0.8).
  const DEFAULT_SURFACE = [0.522, 0.540, 0.604, 1];

  function fromBase64(text) {
    const raw = atob(text);
    const out = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; i++) out[i] = raw.charCodeAt(i);
    return out.buffer;
  }

  function parseGlb(buffer) {
    const dv = new DataView(buffer);
    if (buffer.byteLength < 12 || dv.getUint32(0, true) !== 0x46546c67) throw new Error("not a GLB file");
    let at = 12, json = null, bin = new Uint8Array(0);
    while (at + 8 <= buffer.byteLength) {
      const len = dv.getUint32(at, true), type = dv.getUint32(at + 4, true);
      if (type === 0x4e4f534a) json = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, at + 8, len)));
      else if (type === 0x004e4942) bin = new Uint8Array(buffer, at + 8, len);
      at += 8 + len;
    }
    if (!json) throw new Error("no JSON chunk");
    return { json, bin };
  }

  // The accessor's elements, tightly packed, with what WebGL needs to read them.
  function accessor(g, index) {
    const a = g.json.accessors[index], v = g.json.bufferViews[a.bufferView];
    const [Type, bytes] = COMPONENTS[a.componentType];
    const n = SIZES[a.type], size = n * bytes, stride = v.byteStride || size;
    const base = (v.byteOffset || 0) + (a.byteOffset || 0);
    const out = new Uint8Array(a.count * size);
    for (let e = 0; e < a.count; e++) out.set(g.bin.subarray(base + e * stride, base + e * stride + size), e * size);
    return { data: new Type(out.buffer), n, type: a.componentType, normalized: !!a.normalized, count: a.count, name: a.name || "" };
  }

  // Column-major 4×4 matrices.
  function multiply(a, b) {
    const o = new Float32Array(16);
    for (let c = 0; c < 4; c++) for (let r = 0; r < 4; r++) {
      let s = 0;
      for (let k = 0; k < 4; k++) s += a[k * 4 + r] * b[c * 4 + k];
      o[c * 4 + r] = s;
    }
    return o;
  }
  function nodeMatrix(node) {
    if (node.matrix) return new Float32Array(node.matrix);
    const [x, y, z, w] = node.rotation || [0, 0, 0, 1];
    const [sx, sy, sz] = node.scale || [1, 1, 1];
    const t = node.translation || [0, 0, 0];
    return new Float32Array([
      (1 - 2 * (y * y + z * z)) * sx, 2 * (x * y + z * w) * sx, 2 * (x * z - y * w) * sx, 0,
      2 * (x * y - z * w) * sy, (1 - 2 * (x * x + z * z)) * sy, 2 * (y * z + x * w) * sy, 0,
      2 * (x * z + y * w) * sz, 2 * (y * z - x * w) * sz, (1 - 2 * (x * x + y * y)) * sz, 0,
      t[0], t[1], t[2], 1,
    ]);
  }
  function transformPoint(m, p) {
    return [0, 1, 2].map((r) => m[r] * p[0] + m[4 + r] * p[1] + m[8 + r] * p[2] + m[12 + r]);
  }
  function perspective(fov, aspect, near, far) {
    const f = 1 / Math.tan(fov / 2), nf = 1 / (near - far);
    return new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) * nf, -1, 0, 0, 2 * far * near * nf, 0]);
  }
  function lookAt(eye, target, up) {
    const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    const unit = (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return a.map((x) => x / l); };
    const z = unit(sub(eye, target));
    let x = cross(up, z);
    if (Math.hypot(x[0], x[1], x[2]) < 1e-6) x = cross([1, 0, 0], z);
    x = unit(x);
    const y = cross(z, x);
    const d = (a) => -(a[0] * eye[0] + a[1] * eye[1] + a[2] * eye[2]);
    return new Float32Array([x[0], y[0], z[0], 0, x[1], y[1], z[1], 0, x[2], y[2], z[2], 0, d(x), d(y), d(z), 1]);
  }

  const SHADED_VS = `#version 300 es
    layout(location=0) in vec3 position; layout(location=1) in vec3 normal; layout(location=2) in vec4 vcolor;
    uniform mat4 model, viewProj; uniform float pointSize;
    out vec3 vNormal; out vec3 vWorld; out vec4 vColor;
    void main() {
      vec4 w = model * vec4(position, 1.0);
      vWorld = w.xyz; vNormal = mat3(model) * normal; vColor = vcolor;
      gl_Position = viewProj * w; gl_PointSize = pointSize;
    }`;
  const SHADED_FS = `#version 300 es
    precision highp float;
    in vec3 vNormal; in vec3 vWorld; in vec4 vColor;
    uniform vec4 color; uniform vec3 eye; uniform bool lit; uniform bool vertexColor;
    out vec4 outColor;
    void main() {
      float shade = 1.0;
      if (lit) {
        vec3 n = normalize(vNormal), v = normalize(eye - vWorld);
        shade = 0.3 + 0.7 * abs(dot(n, v));
      }
      vec4 c = vertexColor ? vColor : color;
      outColor = vec4(c.rgb * shade, c.a);
    }`;
  // Triangles with their glTF material: base colour factor × base colour texture (sRGB-decoded
  // by its SRGB8_ALPHA8 format) × COLOR_0, alpha cut (MASK) or kept (BLEND), a tangent-space
  // normal map (with TANGENT: bitangent = cross(N, T)·w, glTF 2.0 §3.7.2.1; without: a frame from
  // screen-space derivatives of position and texture coordinates, V pointing up the image as
  // glTF's normal maps expect), emissive factor × texture. Lit by the page's head light in
  // linear light, written sRGB-encoded (glTF's colours are linear, the screen's sRGB).
  const MATERIAL_VS = `#version 300 es
    layout(location=0) in vec3 position; layout(location=1) in vec3 normal; layout(location=2) in vec4 vcolor;
    layout(location=3) in vec2 uv0; layout(location=4) in vec2 uv1; layout(location=5) in vec4 tangent;
    uniform mat4 model, viewProj;
    out vec3 vNormal; out vec3 vWorld; out vec4 vColor; out vec2 vUv0; out vec2 vUv1; out vec4 vTangent;
    void main() {
      vec4 w = model * vec4(position, 1.0);
      vWorld = w.xyz; vNormal = mat3(model) * normal; vColor = vcolor; vUv0 = uv0; vUv1 = uv1;
      vTangent = vec4(mat3(model) * tangent.xyz, tangent.w);
      gl_Position = viewProj * w;
    }`;
  const MATERIAL_FS = `#version 300 es
    precision highp float;
    in vec3 vNormal; in vec3 vWorld; in vec4 vColor; in vec2 vUv0; in vec2 vUv1; in vec4 vTangent;
    uniform vec4 color; uniform vec3 eye, emissive; uniform bool lit, hasTangent;
    uniform sampler2D baseTex, normalTex, emissiveTex;
    uniform mat3 baseXf, normalXf, emissiveXf;
    uniform int baseSet, normalSet, emissiveSet, alphaMode;
    uniform float normalScale, alphaCutoff;
    out vec4 outColor;
    vec2 uvOf(int set, mat3 xf) { return (xf * vec3(set == 1 ? vUv1 : vUv0, 1.0)).xy; }
    vec3 encodeSrgb(vec3 c) {
      return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
    }
    vec3 mappedNormal(vec3 n) {
      vec2 uv = uvOf(normalSet, normalXf);
      vec3 m = texture(normalTex, uv).xyz * 2.0 - 1.0;
      m.xy *= normalScale;
      vec3 t, b;
      if (hasTangent) {
        t = normalize(vTangent.xyz - n * dot(n, vTangent.xyz));
        b = cross(n, t) * (vTangent.w < 0.0 ? -1.0 : 1.0);
      } else {
        vec3 dp1 = dFdx(vWorld), dp2 = dFdy(vWorld);
        vec2 duv1 = dFdx(uv), duv2 = dFdy(uv);
        vec3 p2 = cross(dp2, n), p1 = cross(n, dp1);
        t = p2 * duv1.x + p1 * duv2.x;
        b = -(p2 * duv1.y + p1 * duv2.y);
        float s = inversesqrt(max(max(dot(t, t), dot(b, b)), 1e-30));
        t *= s; b *= s;
      }
      return normalize(t * m.x + b * m.y + n * m.z);
    }
    void main() {
      vec4 c = color * vColor;
      if (baseSet >= 0) c *= texture(baseTex, uvOf(baseSet, baseXf));
      if (alphaMode == 1 && c.a < alphaCutoff) discard;
      float shade = 1.0;
      if (lit) {
        vec3 n = normalize(vNormal);
        if (normalSet >= 0) n = mappedNormal(n);
        shade = 0.3 + 0.7 * abs(dot(n, normalize(eye - vWorld)));
      }
      vec3 e = emissive;
      if (emissiveSet >= 0) e *= texture(emissiveTex, uvOf(emissiveSet, emissiveXf)).rgb;
      vec3 rgb = clamp(c.rgb * shade + e, 0.0, 1.0);
      outColor = vec4(encodeSrgb(rgb), alphaMode == 2 ? c.a : 1.0);
    }`;
  // Thick edges: every segment an instanced quad offset across the line on screen.
  const EDGE_VS = `#version 300 es
    layout(location=0) in vec3 a; layout(location=1) in vec3 b; layout(location=2) in vec2 corner;
    layout(location=3) in float objectWidth;
    uniform mat4 model, viewProj; uniform vec2 viewport; uniform float width, focal;
    void main() {
      vec4 pa = viewProj * model * vec4(a, 1.0), pb = viewProj * model * vec4(b, 1.0);
      vec2 sa = pa.xy / pa.w * viewport, sb = pb.xy / pb.w * viewport;
      vec2 dir = normalize(sb - sa + vec2(1e-6, 0.0));
      vec4 p = corner.x < 0.5 ? pa : pb;
      float half_px = max(width, 0.5 * objectWidth * focal / p.w);
      vec2 off = vec2(-dir.y, dir.x) * half_px * corner.y;
      gl_Position = vec4(p.xy + off / viewport * p.w, p.zw);
    }`;
  const EDGE_FS = `#version 300 es
    precision highp float; uniform vec4 color; out vec4 outColor;
    void main() { outColor = color; }`;

  function program(gl, vs, fs) {
    const p = gl.createProgram();
    for (const [type, src] of [[gl.VERTEX_SHADER, vs], [gl.FRAGMENT_SHADER, fs]]) {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      gl.attachShader(p, s);
    }
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    const uniforms = {};
    for (let i = 0; i < gl.getProgramParameter(p, gl.ACTIVE_UNIFORMS); i++) {
      const name = gl.getActiveUniform(p, i).name;
      uniforms[name] = gl.getUniformLocation(p, name);
    }
    return { p, u: uniforms };
  }

  function arrayBuffer(gl, target, data) {
    const b = gl.createBuffer();
    gl.bindBuffer(target, b);
    gl.bufferData(target, data, gl.STATIC_DRAW);
    return b;
  }

  function attribute(gl, loc, acc) {
    arrayBuffer(gl, gl.ARRAY_BUFFER, acc.data);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, acc.n, acc.type, acc.normalized, 0, 0);
  }

  function indexData(acc) {
    return acc.type === 5121 ? new Uint16Array(acc.data) : acc.data;
  }

  // The bytes of a data URI's payload without ;base64 (RFC 2397: %XX escapes, else the
  // characters' own codes).
  function percentDecoded(text) {
    const out = [];
    for (let i = 0; i < text.length; i++) {
      if (text[i] === "%" && /^[0-9a-fA-F]{2}$/.test(text.substr(i + 1, 2))) { out.push(parseInt(text.substr(i + 1, 2), 16)); i += 2; }
      else out.push(text.charCodeAt(i) & 255);
    }
    return new Uint8Array(out);
  }

  // An image's encoded bytes and media type (from its buffer view or a data URI), or why the
  // page cannot show it. The Rust side (check.rs) has refused images outside the file.
  function imageSource(g, index) {
    const image = (g.json.images || [])[index];
    if (!image) return `image ${index} does not exist`;
    let bytes, mime = image.mimeType || "";
    if (image.bufferView !== undefined) {
      const v = g.json.bufferViews[image.bufferView];
      bytes = g.bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength);
    } else {
      const m = /^data:([^;,]*)(;base64)?,(.*)$/s.exec(image.uri || "");
      if (!m) return `image ${index} is not inside the file`;
      mime = mime || m[1];
      bytes = m[2] ? new Uint8Array(fromBase64(m[3])) : percentDecoded(m[3]);
    }
    if (!/^image\/(png|jpeg|webp)$/.test(mime)) return `image ${index} (${mime || "no media type"}) is not one a browser decodes`;
    return { bytes, mime };
  }

  // The GPU texture of an image in one colour space (sRGB for colours, linear for normals),
  // decoded asynchronously: `texture` stays null until it is ready, then `redraw` runs. An image
  // that cannot be decoded leaves a note for the overlay.
  function textureOf(gl, g, index, srgb, redraw) {
    const key = `${index} ${srgb}`;
    if (g.looks.has(key)) return g.looks.get(key);
    const slot = { texture: null };
    g.looks.set(key, slot);
    const source = imageSource(g, index);
    if (typeof source === "string") { g.notes.push(source + ": drawn without it"); return slot; }
    const blob = new Blob([source.bytes], { type: source.mime });
    createImageBitmap(blob, { premultiplyAlpha: "none", colorSpaceConversion: "none" })
      .then((bitmap) => {
        const t = gl.createTexture();
        gl.bindTexture(gl.TEXTURE_2D, t);
        gl.texImage2D(gl.TEXTURE_2D, 0, srgb ? gl.SRGB8_ALPHA8 : gl.RGBA8, gl.RGBA, gl.UNSIGNED_BYTE, bitmap);
        gl.generateMipmap(gl.TEXTURE_2D);
        bitmap.close();
        slot.texture = t;
      })
      .catch((e) => { g.notes.push(`image ${index} cannot be decoded (${e.message}): drawn without it`); })
      .then(redraw);
    return slot;
  }

  // A WebGL sampler object for glTF sampler `index` (glTF's defaults: repeat, linear, and
  // trilinear minification, as every texture gets its mipmaps).
  function samplerOf(gl, g, index) {
    const key = `sampler ${index}`;
    if (g.looks.has(key)) return g.looks.get(key);
    const d = (g.json.samplers || [])[index] || {};
    const s = gl.createSampler();
    gl.samplerParameteri(s, gl.TEXTURE_WRAP_S, d.wrapS || gl.REPEAT);
    gl.samplerParameteri(s, gl.TEXTURE_WRAP_T, d.wrapT || gl.REPEAT);
    gl.samplerParameteri(s, gl.TEXTURE_MAG_FILTER, d.magFilter || gl.LINEAR);
    gl.samplerParameteri(s, gl.TEXTURE_MIN_FILTER, d.minFilter || gl.LINEAR_MIPMAP_LINEAR);
    g.looks.set(key, s);
    return s;
  }

  // KHR_texture_transform as a column-major 3×3 matrix: scale, then rotation (u' = c·u + s·v,
  // v' = −s·u + c·v), then offset.
  function uvMatrix(x) {
    const [ox, oy] = x.offset || [0, 0], [sx, sy] = x.scale || [1, 1], r = x.rotation || 0;
    const c = Math.cos(r), s = Math.sin(r);
    return new Float32Array([sx * c, -sx * s, 0, sy * s, sy * c, 0, ox, oy, 1]);
  }

  // A material's texture slot (a textureInfo): its texture, sampler, coordinate set and
  // transform; null when absent or not drawable (with a note).
  function textureSlot(gl, g, info, srgb, redraw, what) {
    if (!info) return null;
    const tex = (g.json.textures || [])[info.index];
    const x = (info.extensions || {}).KHR_texture_transform || {};
    const set = x.texCoord !== undefined ? x.texCoord : info.texCoord || 0;
    if (!tex || tex.source === undefined) { g.notes.push(`${what} texture ${info.index} has no image the page reads`); return null; }
    if (set > 1) { g.notes.push(`${what} texture ${info.index} reads TEXCOORD_${set}, which the page does not`); return null; }
    return { image: textureOf(gl, g, tex.source, srgb, redraw), sampler: samplerOf(gl, g, tex.sampler), set, xf: uvMatrix(x) };
  }

  // What the material program needs of material `index` (none: the page's grey), once per file.
  function materialOf(gl, g, index, redraw) {
    const key = `material ${index}`;
    if (g.looks.has(key)) return g.looks.get(key);
    const mat = (g.json.materials || [])[index];
    const pbr = (mat && mat.pbrMetallicRoughness) || {};
    const strength = ((mat && mat.extensions) || {}).KHR_materials_emissive_strength;
    const emissive = ((mat && mat.emissiveFactor) || [0, 0, 0]).map((e) => e * ((strength && strength.emissiveStrength) || 1));
    const out = {
      color: pbr.baseColorFactor || (mat ? [1, 1, 1, 1] : DEFAULT_SURFACE),
      base: textureSlot(gl, g, pbr.baseColorTexture, true, redraw, "base colour"),
      normal: mat ? textureSlot(gl, g, mat.normalTexture, false, redraw, "normal") : null,
      normalScale: mat && mat.normalTexture && mat.normalTexture.scale !== undefined ? mat.normalTexture.scale : 1,
      emissive,
      emissiveTexture: mat ? textureSlot(gl, g, mat.emissiveTexture, true, redraw, "emissive") : null,
      alphaMode: { MASK: 1, BLEND: 2 }[mat && mat.alphaMode] || 0,
      alphaCutoff: mat && mat.alphaCutoff !== undefined ? mat.alphaCutoff : 0.5,
      doubleSided: !!(mat && mat.doubleSided),
    };
    g.looks.set(key, out);
    return out;
  }

  // A GPU draw of one primitive: triangles with the material program, points with the shaded
  // one, lines as quads.
  function uploadPrimitive(gl, g, prim, model, redraw) {
    const mode = prim.mode === undefined ? 4 : prim.mode;
    const pos = accessor(g, prim.attributes.POSITION);
    const optional = (name) => (prim.attributes[name] !== undefined ? accessor(g, prim.attributes[name]) : null);
    const nor = optional("NORMAL");
    const idx = prim.indices !== undefined ? indexData(accessor(g, prim.indices)) : null;
    const mat = g.json.materials && prim.material !== undefined ? g.json.materials[prim.material] : {};
    const pbr = mat.pbrMetallicRoughness || {};
    const color = pbr.baseColorFactor || (mode === 4 ? [0.75, 0.76, 0.8, 1] : [0.1, 0.1, 0.12, 1]);
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    let draw;
    if (mode === 1 || mode === 3 || mode === 2) {
      draw = edgeDraw(gl, pos, idx, mode, optional("_WIDTH"));
    } else {
      attribute(gl, 0, pos);
      if (nor) attribute(gl, 1, nor);
      else gl.vertexAttrib3f(1, 0, 0, 1);
      let count = pos.count, type = null;
      if (idx) {
        arrayBuffer(gl, gl.ELEMENT_ARRAY_BUFFER, idx);
        count = idx.length;
        type = idx instanceof Uint32Array ? gl.UNSIGNED_INT : gl.UNSIGNED_SHORT;
      }
      draw = { kind: "shaded", mode, count, type, lit: !!nor && mode >= 4 };
      if (mode >= 4) {
        // Absent attributes are constants: white vertex colour, (0, 0) coordinates, no tangent.
        const looks = [[2, "COLOR_0", [1, 1, 1, 1]], [3, "TEXCOORD_0", [0, 0, 0, 1]], [4, "TEXCOORD_1", [0, 0, 0, 1]], [5, "TANGENT", [1, 0, 0, 1]]];
        for (const [loc, name, constant] of looks) {
          const acc = optional(name);
          if (acc) attribute(gl, loc, acc);
          else gl.vertexAttrib4fv(loc, constant);
        }
        draw.kind = "material";
        draw.material = materialOf(gl, g, prim.material, redraw);
        draw.hasTangent = !!optional("TANGENT");
        draw.centre = boxCentre(g.json.accessors[prim.attributes.POSITION], model);
      } else {
        gl.vertexAttrib4f(2, 1, 1, 1, 1);
      }
    }
    gl.bindVertexArray(null);
    const triangles = mode === 4 ? (idx ? idx.length : pos.count) / 3 : 0;
    return Object.assign(draw, { vao, model, color, triangles });
  }

  // The world position of the centre of an accessor's bounds (its origin without bounds).
  function boxCentre(a, model) {
    const c = a.min && a.max ? [0, 1, 2].map((k) => (a.min[k] + a.max[k]) / 2) : [0, 0, 0];
    return transformPoint(model, c);
  }

  // Segments as instances: endpoints (and a width in object units, from _WIDTH) per instance,
  // a unit quad's corners per vertex.
  function edgeDraw(gl, pos, idx, mode, widths) {
    const order = idx || Array.from({ length: pos.count }, (_, i) => i);
    const pairs = [];
    const step = mode === 1 ? 2 : 1;
    const last = mode === 2 ? order.length : order.length - 1;
    for (let i = 0; i + (mode === 1 ? 1 : 0) < last; i += step) pairs.push(order[i], order[(i + 1) % order.length]);
    const a = new Float32Array(pairs.length / 2 * 3), b = new Float32Array(pairs.length / 2 * 3);
    const scale = pos.normalized ? { 5120: 127, 5121: 255, 5122: 32767, 5123: 65535 }[pos.type] || 1 : 1;
    for (let s = 0; s < pairs.length / 2; s++) for (let c = 0; c < 3; c++) {
      a[s * 3 + c] = pos.data[pairs[2 * s] * 3 + c] / scale;
      b[s * 3 + c] = pos.data[pairs[2 * s + 1] * 3 + c] / scale;
    }
    for (const [loc, data] of [[0, a], [1, b]]) {
      arrayBuffer(gl, gl.ARRAY_BUFFER, data);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 3, gl.FLOAT, false, 0, 0);
      gl.vertexAttribDivisor(loc, 1);
    }
    arrayBuffer(gl, gl.ARRAY_BUFFER, new Float32Array([0, -1, 1, -1, 1, 1, 0, -1, 1, 1, 0, 1]));
    gl.enableVertexAttribArray(2);
    gl.vertexAttribPointer(2, 2, gl.FLOAT, false, 0, 0);
    if (widths && widths.type === 5126 && widths.n === 1) {
      // One width per segment: the larger of its two ends'.
      const w = new Float32Array(pairs.length / 2);
      for (let s = 0; s < w.length; s++) w[s] = Math.max(widths.data[pairs[2 * s]], widths.data[pairs[2 * s + 1]]);
      arrayBuffer(gl, gl.ARRAY_BUFFER, w);
      gl.enableVertexAttribArray(3);
      gl.vertexAttribPointer(3, 1, gl.FLOAT, false, 0, 0);
      gl.vertexAttribDivisor(3, 1);
    } else {
      gl.vertexAttrib1f(3, 0);
    }
    return { kind: "edges", count: pairs.length / 2 };
  }

  function drawsOfNode(gl, g, index, parent, out, redraw) {
    const node = g.json.nodes[index];
    const m = multiply(parent, nodeMatrix(node));
    if (node.mesh !== undefined) {
      for (const prim of g.json.meshes[node.mesh].primitives) {
        if (prim.attributes.POSITION !== undefined) out.push(uploadPrimitive(gl, g, prim, m, redraw));
      }
    }
    for (const c of node.children || []) drawsOfNode(gl, g, c, m, out, redraw);
    return out;
  }

  const IDENTITY = new Float32Array([1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]);
  const IDENTITY3 = new Float32Array([1, 0, 0, 0, 1, 0, 0, 0, 1]);

  // The box of every position accessor under the scene's nodes, in world units.
  function sceneBounds(g, roots) {
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    const visit = (index, parent) => {
      const node = g.json.nodes[index], m = multiply(parent, nodeMatrix(node));
      if (node.mesh !== undefined) for (const prim of g.json.meshes[node.mesh].primitives) {
        const a = g.json.accessors[prim.attributes.POSITION];
        if (!a || !a.min || !a.max) continue;
        for (let c = 0; c < 8; c++) {
          const p = transformPoint(m, [0, 1, 2].map((k) => ((c >> k) & 1 ? a.max[k] : a.min[k])));
          for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
        }
      }
      for (const ch of node.children || []) visit(ch, m);
    };
    for (const r of roots) visit(r, IDENTITY);
    return { lo, hi };
  }

  function octantName(d) {
    return "order" + (d[0] < 0 ? "-" : "+") + "x" + (d[1] < 0 ? "-" : "+") + "y" + (d[2] < 0 ? "-" : "+") + "z";
  }

  // Layered shells: every layer's vertices (the triangle primitives of `meshes`) concatenated (as
  // the orders index them), a per-vertex alpha from its layer's material, the eight orders
  // ([octant name, accessor] pairs) as index buffers; `radius` is the filter's, in object units.
  function layeredModel(gl, g, meshes, orderAccessors, radius) {
    const positions = [], normals = [], alphas = [], layers = [];
    let first = 0;
    for (const mesh of meshes.map((i) => g.json.meshes[i])) for (const prim of mesh.primitives) {
      if ((prim.mode === undefined ? 4 : prim.mode) !== 4) continue;
      const pos = accessor(g, prim.attributes.POSITION);
      if (pos.type !== 5126) throw new Error("layered shells must have float positions");
      const mat = (g.json.materials || [])[prim.material] || {};
      const rgba = (mat.pbrMetallicRoughness || {}).baseColorFactor || [1, 1, 1, 1];
      positions.push(pos.data);
      const nor = prim.attributes.NORMAL !== undefined ? accessor(g, prim.attributes.NORMAL) : null;
      normals.push(nor && nor.type === 5126 ? nor.data : new Float32Array(pos.count * 3));
      const colors = new Float32Array(pos.count * 4);
      for (let v = 0; v < pos.count; v++) colors.set(rgba, v * 4);
      alphas.push(colors);
      const iso = (prim.extras || mesh.extras || {}).isodensity;
      const indices = prim.indices !== undefined ? indexData(accessor(g, prim.indices)) : Uint32Array.from({ length: pos.count }, (_, i) => i);
      layers.push({ first, count: pos.count, rgba, iso, indices });
      first += pos.count;
    }
    const join = (parts, T) => { const out = new T(parts.reduce((s, p) => s + p.length, 0)); let at = 0; for (const p of parts) { out.set(p, at); at += p.length; } return out; };
    const vao = gl.createVertexArray();
    gl.bindVertexArray(vao);
    for (const [loc, data, n] of [[0, join(positions, Float32Array), 3], [1, join(normals, Float32Array), 3], [2, join(alphas, Float32Array), 4]]) {
      arrayBuffer(gl, gl.ARRAY_BUFFER, data);
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, n, gl.FLOAT, false, 0, 0);
    }
    gl.bindVertexArray(null);
    const orders = {};
    for (const [name, i] of orderAccessors) {
      const acc = accessor(g, i), data = indexData(acc);
      const type = data instanceof Uint32Array ? gl.UNSIGNED_INT : gl.UNSIGNED_SHORT;
      orders[name] = { buffer: arrayBuffer(gl, gl.ELEMENT_ARRAY_BUFFER, data), count: acc.count, type };
    }
    // The single surface: the layer nearest isodensity 0.5, with its own indices shifted.
    const single = layers.reduce((best, l) => (Math.abs((l.iso ?? 0.5) - 0.5) < Math.abs((best.iso ?? 0.5) - 0.5) ? l : best), layers[0]);
    const shifted = new Uint32Array(single.indices.length);
    for (let i = 0; i < shifted.length; i++) shifted[i] = single.indices[i] + single.first;
    return {
      vao, orders, color: layers[0].rgba, radius,
      single: { buffer: arrayBuffer(gl, gl.ELEMENT_ARRAY_BUFFER, shifted), count: shifted.length, rgba: single.rgba },
      triangles: layers.reduce((s, l) => s + l.indices.length / 3, 0),
    };
  }

  // The scene's root nodes named LOD0, LOD1, … LODn−1 (n ≥ 2, each once: voxlod's lod-nodes
  // layout, and the importers' LOD-group convention), finest first; null when there are none.
  function lodNodeIds(g, roots) {
    const ids = [];
    let named = 0;
    for (const r of roots) {
      const m = /^LOD(\d+)$/.exec((g.json.nodes[r] || {}).name || "");
      if (m && Number(m[1]) < roots.length) { ids[Number(m[1])] = r; named += 1; }
    }
    return ids.length >= 2 && named === ids.length && !ids.includes(undefined) ? ids : null;
  }

  // MSFT_screencoverage for levels without it, by the rule voxlod's writer uses for its default:
  // level k is left below half the square root of level k+1's share of level 0's triangles (its
  // node's extras.voxlod.triangles, else the triangles drawn); 0 for the last. Equal steps
  // 1/2, 1/3, … where the triangles do not decrease.
  function coverageByTriangles(g, ids, levels) {
    const counted = levels.map((draws) => draws.reduce((s, d) => s + d.triangles, 0));
    const triangles = ids.map((id, k) => (((g.json.nodes[id].extras || {}).voxlod || {}).triangles) || counted[k]);
    const decreasing = triangles.every((t, k) => k === 0 || (t > 0 && t < triangles[k - 1]));
    return ids.map((_, k) => {
      if (k === ids.length - 1) return 0;
      return decreasing ? 0.5 * Math.sqrt(triangles[k + 1] / triangles[0]) : 1 / (k + 2);
    });
  }

  function loadModel(gl, entry, redraw) {
    const g = parseGlb(fromBase64(entry.glb));
    g.looks = new Map();
    g.notes = [];
    const sceneIndex = g.json.scene || 0;
    const scene = (g.json.scenes || [])[sceneIndex] || { nodes: (g.json.nodes || []).map((_, i) => i) };
    const extras = (scene.extras || {}).voxlod || {};
    const named = (g.json.accessors || []).map((a, i) => [a.name || "", i]);
    const orderAccessors = named.filter(([n]) => /^order[+-]x[+-]y[+-]z$/.test(n));
    const { lo, hi } = sceneBounds(g, scene.nodes);
    const centre = [0, 1, 2].map((k) => (lo[k] + hi[k]) / 2);
    const diameter = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
    const model = { name: entry.name, centre, diameter, kind: "mesh" };
    if (orderAccessors.length === 8) {
      const radius = extras.radius || (extras.grid ? Math.max(...extras.grid.spacing) : 0);
      const meshes = (g.json.meshes || []).map((_, i) => i);
      return Object.assign(model, { kind: "layered", layered: layeredModel(gl, g, meshes, orderAccessors, radius) });
    }
    const root = g.json.nodes && g.json.nodes[scene.nodes[0]];
    const lod = root && root.extensions && root.extensions.MSFT_lod;
    const lodNodes = lod ? null : lodNodeIds(g, scene.nodes);
    if (lodNodes) {
      // Root nodes beside the levels are drawn with every level.
      const others = scene.nodes.filter((n) => !lodNodes.includes(n)).flatMap((n) => drawsOfNode(gl, g, n, IDENTITY, [], redraw));
      model.kind = "lod";
      model.levelNames = lodNodes.map((id) => g.json.nodes[id].name);
      model.levels = lodNodes.map((id) => drawsOfNode(gl, g, id, IDENTITY, [], redraw).concat(others));
      model.coverage = coverageByTriangles(g, lodNodes, model.levels);
      model.viewportHeight = (extras.screen_coverage || {}).viewport_height || 1080;
      return Object.assign(model, { notes: g.notes });
    }
    if (lod) {
      const ids = [scene.nodes[0]].concat(lod.ids);
      const levelOrders = ids.map((_, k) => named.filter(([n]) => n.startsWith(`level ${k} order`)).map(([n, i]) => [n.slice(`level ${k} `.length), i]));
      model.levelNames = ids.map((id) => g.json.nodes[id].name || "node " + id);
      if (levelOrders.every((o) => o.length === 8)) {
        // A layered chain: each level's radius from its node's extras.
        model.kind = "layered lod";
        model.levels = ids.map((id, k) => layeredModel(gl, g, [g.json.nodes[id].mesh], levelOrders[k], (((g.json.nodes[id].extras || {}).voxlod || {}).radius) || 0));
        const sc = extras.screen_coverage || {};
        model.radiusLimit = sc.measure === "filter radius" && sc.tolerance > 0 ? sc.tolerance : RADIUS_LIMIT_PX;
        return model;
      }
      model.kind = "lod";
      model.levels = ids.map((id) => drawsOfNode(gl, g, id, IDENTITY, [], redraw));
      model.coverage = (root.extras || {}).MSFT_screencoverage || ids.map((_, i) => (i === ids.length - 1 ? 0 : 1 / (i + 2)));
      const sc = extras.screen_coverage || {};
      model.viewportHeight = sc.viewport_height || 1080;
      if (sc.diameter) model.diameter = sc.diameter;
      return Object.assign(model, { notes: g.notes });
    }
    model.draws = scene.nodes.flatMap((n) => drawsOfNode(gl, g, n, IDENTITY, [], redraw));
    return Object.assign(model, { notes: g.notes });
  }

  function start() {
    const canvas = document.getElementById("view");
    const gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: true });
    const overlay = document.getElementById("overlay");
    if (!gl) { overlay.textContent = "WebGL2 is not available"; document.title = "voxlod: no webgl2"; return; }
    const shaded = program(gl, SHADED_VS, SHADED_FS), edges = program(gl, EDGE_VS, EDGE_FS);
    const material = program(gl, MATERIAL_VS, MATERIAL_FS);
    gl.useProgram(material.p);
    ["baseTex", "normalTex", "emissiveTex"].forEach((name, unit) => gl.uniform1i(material.u[name], unit));
    const white = gl.createTexture();
    gl.bindTexture(gl.TEXTURE_2D, white);
    gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA8, 1, 1, 0, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array([255, 255, 255, 255]));
    const entries = JSON.parse(document.getElementById("voxlod-data").textContent);
    // Images decode after the first frame; each one ready draws the view again.
    const models = entries.map((e) => loadModel(gl, e, () => render()));
    const state = { model: 0, distance: 0, dir: [0.4, 0.3, 1.0] };
    const resetDistance = () => { state.distance = 2.0 * models[state.model].diameter; };
    resetDistance();

    function readHash() {
      const params = new URLSearchParams(location.hash.slice(1));
      if (params.has("model")) state.model = Math.min(models.length - 1, Math.max(0, parseInt(params.get("model"), 10) || 0));
      const cam = params.get("camera");
      if (cam) {
        const v = cam.split(",").map(Number);
        if (v.length === 4 && v.every(Number.isFinite) && v[0] > 0) { state.distance = v[0]; state.dir = v.slice(1); }
      }
    }

    function chooseLevel(m, distance, height) {
      const coverage = m.diameter / (2 * distance * Math.tan(FOV / 2)) * height / m.viewportHeight;
      for (let k = 0; k < m.coverage.length; k++) if (coverage > m.coverage[k]) return Math.min(k, m.levels.length - 1);
      return m.levels.length - 1;
    }

    function drawShaded(d, viewProj, eye, override) {
      gl.useProgram(shaded.p);
      gl.uniformMatrix4fv(shaded.u.model, false, d.model);
      gl.uniformMatrix4fv(shaded.u.viewProj, false, viewProj);
      gl.uniform3fv(shaded.u.eye, eye);
      gl.uniform4fv(shaded.u.color, override || d.color);
      gl.uniform1i(shaded.u.lit, d.lit ? 1 : 0);
      gl.uniform1i(shaded.u.vertexColor, 0);
      gl.uniform1f(shaded.u.pointSize, POINT_PX);
      gl.bindVertexArray(d.vao);
      if (d.type) gl.drawElements(d.mode, d.count, d.type, 0);
      else gl.drawArrays(d.mode, 0, d.count);
    }

    // One texture slot on `unit`: its image when decoded (else the white stand-in), its sampler,
    // coordinate set and transform; set −1 turns the slot off.
    function bindSlot(unit, slot, name, standIn) {
      const ready = slot && slot.image.texture;
      gl.activeTexture(gl.TEXTURE0 + unit);
      gl.bindTexture(gl.TEXTURE_2D, ready || white);
      gl.bindSampler(unit, slot ? slot.sampler : null);
      gl.uniform1i(material.u[name + "Set"], slot && (ready || standIn) ? slot.set : -1);
      gl.uniformMatrix3fv(material.u[name + "Xf"], false, slot ? slot.xf : IDENTITY3);
    }

    function drawMaterial(d, viewProj, eye) {
      const m = d.material;
      gl.useProgram(material.p);
      gl.uniformMatrix4fv(material.u.model, false, d.model);
      gl.uniformMatrix4fv(material.u.viewProj, false, viewProj);
      gl.uniform3fv(material.u.eye, eye);
      gl.uniform4fv(material.u.color, m.color);
      gl.uniform1i(material.u.lit, d.lit ? 1 : 0);
      gl.uniform1i(material.u.hasTangent, d.hasTangent ? 1 : 0);
      bindSlot(0, m.base, "base", true);
      bindSlot(1, m.normal, "normal", false);
      bindSlot(2, m.emissiveTexture, "emissive", false);
      gl.uniform1f(material.u.normalScale, m.normalScale);
      gl.uniform3fv(material.u.emissive, m.emissiveTexture && !m.emissiveTexture.image.texture ? [0, 0, 0] : m.emissive);
      gl.uniform1i(material.u.alphaMode, m.alphaMode);
      gl.uniform1f(material.u.alphaCutoff, m.alphaCutoff);
      // A single-sided blended surface seen from its back is culled (glTF 2.0 §3.9.4): drawn
      // without depth writes, a closed mesh's back would show through its front. A mirroring
      // node turns the winding over.
      const cull = m.alphaMode === 2 && !m.doubleSided;
      if (cull) {
        const a = d.model;
        const det = a[0] * (a[5] * a[10] - a[6] * a[9]) - a[4] * (a[1] * a[10] - a[2] * a[9]) + a[8] * (a[1] * a[6] - a[2] * a[5]);
        gl.enable(gl.CULL_FACE);
        gl.frontFace(det < 0 ? gl.CW : gl.CCW);
      }
      gl.bindVertexArray(d.vao);
      if (d.type) gl.drawElements(d.mode, d.count, d.type, 0);
      else gl.drawArrays(d.mode, 0, d.count);
      if (cull) {
        gl.disable(gl.CULL_FACE);
        gl.frontFace(gl.CCW);
      }
      for (let unit = 0; unit < 3; unit++) gl.bindSampler(unit, null);
    }

    function drawEdges(d, viewProj) {
      gl.useProgram(edges.p);
      gl.uniformMatrix4fv(edges.u.model, false, d.model);
      gl.uniformMatrix4fv(edges.u.viewProj, false, viewProj);
      gl.uniform2f(edges.u.viewport, gl.drawingBufferWidth / 2, gl.drawingBufferHeight / 2);
      gl.uniform1f(edges.u.width, EDGE_PX / 2);
      gl.uniform1f(edges.u.focal, gl.drawingBufferHeight / 2 / Math.tan(FOV / 2));
      gl.uniform4fv(edges.u.color, d.color);
      gl.bindVertexArray(d.vao);
      gl.drawArraysInstanced(gl.TRIANGLES, 0, 6, d.count);
    }

    // Opaque and masked draws first, then BLEND materials back to front (by their bounds'
    // centres) over them without writing depth.
    function drawDraws(draws, viewProj, eye) {
      gl.enable(gl.DEPTH_TEST);
      const blended = (d) => d.kind === "material" && d.material.alphaMode === 2;
      const kinds = { edges: drawEdges, shaded: drawShaded, material: drawMaterial };
      for (const d of draws) if (!blended(d)) kinds[d.kind](d, viewProj, eye);
      const far = (d) => Math.hypot(d.centre[0] - eye[0], d.centre[1] - eye[1], d.centre[2] - eye[2]);
      const back = draws.filter(blended).sort((a, b) => far(b) - far(a));
      if (back.length) {
        gl.enable(gl.BLEND);
        gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
        gl.depthMask(false);
        for (const d of back) drawMaterial(d, viewProj, eye);
        gl.depthMask(true);
        gl.disable(gl.BLEND);
      }
      return draws.reduce((s, d) => s + d.triangles, 0);
    }

    // The size of a pixel in object units at the object's distance.
    const pixelSize = (distance) => 2 * distance * Math.tan(FOV / 2) / gl.drawingBufferHeight;

    // The coarsest level of a layered chain whose filter radius on screen is within the limit
    // (level 0 when none is: drawn as its single surface).
    function chooseLayeredLevel(m, distance) {
      let level = 0;
      for (let k = 0; k < m.levels.length; k++) if (m.levels[k].radius / pixelSize(distance) <= m.radiusLimit) level = k;
      return level;
    }

    function drawLayered(L, limit, viewProj, eye, view) {
      const radiusPx = L.radius / pixelSize(view.distance);
      gl.useProgram(shaded.p);
      gl.uniformMatrix4fv(shaded.u.model, false, IDENTITY);
      gl.uniformMatrix4fv(shaded.u.viewProj, false, viewProj);
      gl.uniform3fv(shaded.u.eye, eye);
      gl.uniform1i(shaded.u.lit, 1);
      gl.bindVertexArray(L.vao);
      if (L.radius > 0 && radiusPx > limit) {
        gl.enable(gl.DEPTH_TEST);
        gl.uniform4fv(shaded.u.color, [L.single.rgba[0], L.single.rgba[1], L.single.rgba[2], 1]);
        gl.uniform1i(shaded.u.vertexColor, 0);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, L.single.buffer);
        gl.drawElements(gl.TRIANGLES, L.single.count, gl.UNSIGNED_INT, 0);
        return { triangles: L.single.count / 3, order: "single surface", radiusPx, patch: 8 };
      }
      const name = octantName(view.sight);
      const order = L.orders[name];
      gl.disable(gl.DEPTH_TEST);
      gl.enable(gl.BLEND);
      gl.blendFuncSeparate(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA, gl.ONE, gl.ONE_MINUS_SRC_ALPHA);
      gl.uniform4fv(shaded.u.color, L.color);
      gl.uniform1i(shaded.u.vertexColor, 1);
      gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, order.buffer);
      gl.drawElements(gl.TRIANGLES, order.count, order.type, 0);
      gl.disable(gl.BLEND);
      const octant = (view.sight[0] < 0) << 2 | (view.sight[1] < 0) << 1 | (view.sight[2] < 0);
      return { triangles: order.count / 3, order: name, radiusPx, patch: octant };
    }

    function patch(colour, row = 0) {
      gl.enable(gl.SCISSOR_TEST);
      gl.scissor(0, gl.drawingBufferHeight - 24 * (row + 1), 24, 24);
      gl.clearColor(colour[0] / 255, colour[1] / 255, colour[2] / 255, 1);
      gl.clear(gl.COLOR_BUFFER_BIT);
      gl.disable(gl.SCISSOR_TEST);
    }

    function render() {
      const m = models[state.model];
      const width = canvas.clientWidth, height = canvas.clientHeight;
      if (canvas.width !== width || canvas.height !== height) { canvas.width = width; canvas.height = height; }
      gl.viewport(0, 0, gl.drawingBufferWidth, gl.drawingBufferHeight);
      gl.clearColor(1, 1, 1, 1);
      gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
      const len = Math.hypot(...state.dir) || 1;
      const dir = state.dir.map((x) => x / len);
      const eye = [0, 1, 2].map((k) => m.centre[k] + dir[k] * state.distance);
      const near = Math.max(state.distance - m.diameter, state.distance * 1e-3, 1e-6);
      const far = state.distance + m.diameter;
      const up = Math.abs(dir[1]) > 0.99 ? [0, 0, 1] : [0, 1, 0];
      const viewProj = multiply(perspective(FOV, gl.drawingBufferWidth / gl.drawingBufferHeight, near, far), lookAt(eye, m.centre, up));
      const view = { distance: state.distance, sight: dir.map((x) => -x) };
      let text, title;
      if (m.kind === "lod") {
        const level = chooseLevel(m, state.distance, gl.drawingBufferHeight);
        const triangles = drawDraws(m.levels[level], viewProj, eye);
        patch(PALETTE[level % PALETTE.length]);
        text = `${m.name}: ${m.levelNames[level]} (${level + 1} of ${m.levels.length}), ${triangles} triangles`;
        title = `voxlod level=${level} triangles=${triangles}`;
      } else if (m.kind === "layered") {
        const r = drawLayered(m.layered, RADIUS_LIMIT_PX, viewProj, eye, view);
        patch(r.patch < PALETTE.length ? PALETTE[r.patch] : [0, 0, 0]);
        text = `${m.name}: layered, ${r.order}, ${r.triangles} triangles, filter radius ${r.radiusPx.toFixed(2)} px`;
        title = `voxlod order=${r.order} triangles=${r.triangles}`;
      } else if (m.kind === "layered lod") {
        const level = chooseLayeredLevel(m, state.distance);
        const r = drawLayered(m.levels[level], m.radiusLimit, viewProj, eye, view);
        patch(r.patch < PALETTE.length ? PALETTE[r.patch] : [0, 0, 0]);
        patch(PALETTE[level % PALETTE.length], 1);
        text = `${m.name}: ${m.levelNames[level]} (${level + 1} of ${m.levels.length}), layered, ${r.order}, ${r.triangles} triangles, filter radius ${r.radiusPx.toFixed(2)} px`;
        title = `voxlod level=${level} order=${r.order} triangles=${r.triangles}`;
      } else {
        const triangles = drawDraws(m.draws, viewProj, eye);
        text = `${m.name}: ${triangles} triangles`;
        title = `voxlod triangles=${triangles}`;
      }
      const notes = m.notes && m.notes.length ? ` · ${m.notes.join("; ")}` : "";
      overlay.textContent = `${text} · distance ${state.distance.toPrecision(4)}${notes}`;
      document.title = title;
    }

    function orbit() {
      let last = null;
      canvas.addEventListener("pointerdown", (e) => { last = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
      canvas.addEventListener("pointerup", () => { last = null; });
      canvas.addEventListener("pointermove", (e) => {
        if (!last) return;
        const [dx, dy] = [e.clientX - last[0], e.clientY - last[1]];
        last = [e.clientX, e.clientY];
        const [x, y, z] = state.dir, r = Math.hypot(x, y, z) || 1;
        let az = Math.atan2(x, z) - dx * 0.01, el = Math.asin(Math.max(-1, Math.min(1, y / r))) + dy * 0.01;
        el = Math.max(-1.55, Math.min(1.55, el));
        state.dir = [Math.cos(el) * Math.sin(az), Math.sin(el), Math.cos(el) * Math.cos(az)];
        requestAnimationFrame(render);
      });
      canvas.addEventListener("wheel", (e) => { e.preventDefault(); state.distance *= Math.exp(e.deltaY * 0.001); requestAnimationFrame(render); }, { passive: false });
      window.addEventListener("keydown", (e) => {
        const k = parseInt(e.key, 10);
        if (k >= 1 && k <= models.length) { state.model = k - 1; resetDistance(); requestAnimationFrame(render); }
      });
    }

    readHash();
    window.addEventListener("hashchange", () => { readHash(); render(); });
    window.addEventListener("resize", render);
    window.voxlodView = {
      setCamera(distance, dir) { state.distance = distance; state.dir = dir.slice(); render(); },
      state: () => ({ model: state.model, distance: state.distance, dir: state.dir.slice(), title: document.title }),
    };
    orbit();
    render();
  }

  try { start(); } catch (e) {
    document.getElementById("overlay").textContent = "voxlod view: " + e.message;
    document.title = "voxlod error: " + e.message;
  }
})();
