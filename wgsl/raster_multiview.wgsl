// The single-pass cube: every face the lens reaches in one multiview render pass, one view per
// face (the view index is the face), shaded forward. wgpu has no geometry shaders, whose layered
// rendering is the other classic way; this needs `Features::MULTIVIEW`, so it is a module of its
// own that adapters without multiview never compile.
#import raster

@vertex
fn multiview_vs(@builtin(vertex_index) vertex: u32, @builtin(view_index) face: u32) -> Varyings {
    return face_vertex(vertex, face);
}

// The views share one scissor rectangle (the union of the faces' regions), so each view drops
// the fragments outside its own region before shading them.
@fragment
fn multiview_fs(in: Varyings, @builtin(view_index) face: u32) -> @location(0) vec4<f32> {
    // Derivatives before the discard, in uniform control flow.
    let lod = fragment_lod(in);
    if !in_region(face, vec2<u32>(in.position.xy)) {
        discard;
    }
    return vec4<f32>(raster_shade(in.slot, in.bary, in.world, lod), 1.0);
}
