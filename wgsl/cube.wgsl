// The cube map around a point, twin of `fisheye_rt::cube`: which face a direction lands on and
// its UV there (for the camera's cube and for point lights' shadow cubes). The face table
// CUBE_FACES (face-to-cube matrices: columns right, down, forward) is generated from
// `fisheye_rt::cube::FACES`.

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
