// The cube map around the camera, twin of `fisheye_rt::cube`: which face a direction lands on
// and its UV there, and bilinear sampling of faces stored with a one-texel border. The face
// table CUBE_FACES (face-to-camera matrices: columns right, down, forward) is generated from
// `fisheye_rt::cube::FACES`.

// Six faces of (size + 2)² texels, row-major, linear RGB (w unused by sampling).
@group(0) @binding(2) var<storage, read> cube_texels: array<vec4<f32>>;

struct FaceUv {
    face: u32,
    uv: vec2<f32>,
}

// The axis of largest magnitude picks the face; exact ties go to x over y over z, a zero
// component counts as positive, and the zero vector maps to the centre of +z.
fn cube_face_uv(d: vec3<f32>) -> FaceUv {
    let a = abs(d);
    var axis = 2u;
    if a.x >= a.y && a.x >= a.z {
        axis = 0u;
    } else if a.y >= a.z {
        axis = 1u;
    }
    if a[axis] == 0.0 {
        return FaceUv(4u, vec2<f32>(0.5));
    }
    let face = 2u * axis + select(0u, 1u, d[axis] < 0.0);
    let m = CUBE_FACES[face];
    // Each axis is a ±1 permutation, so these dot products are exact component selections.
    let major = dot(d, m[2]);
    return FaceUv(face, (vec2<f32>(dot(d, m[0]), dot(d, m[1])) / major + 1.0) * 0.5);
}

// Bilinear lookup at `uv` of `face` in `texels`: six faces of (size + 2)² texels, row-major,
// the border holding samples just past each edge, so the four texels read always exist.
fn cube_sample(face: u32, uv: vec2<f32>, size: u32) -> vec4<f32> {
    let side = size + 2u;
    let st = uv * f32(size) + 0.5;
    let base = floor(st);
    let f = st - base;
    let x = min(u32(max(base.x, 0.0)), side - 2u);
    let y = min(u32(max(base.y, 0.0)), side - 2u);
    let row = (face * side + y) * side + x;
    let top = mix(cube_texels[row], cube_texels[row + 1u], f.x);
    let bottom = mix(cube_texels[row + side], cube_texels[row + side + 1u], f.x);
    return mix(top, bottom, f.y);
}
