// Adaptive sampling's listing kernels but `classify` (steps 2, 4 and 5 of `adaptive.wgsl`'s
// header): `midpoints` lists the midpoints of the blocks refined at level 0; `select_pixels`
// lists the traced pixels whose colour bends, `more` those whose estimate asks for every
// sample, `untraced` the interpolated ones. Each invocation of the per-pixel listers looks at
// ADAPTIVE_STRIP pixels side by side, so that a workgroup's barriers and global atomic serve
// more pixels.
#import adaptive

// Lists the midpoints that the blocks refined at level 0 need: the half-blocks' corners that
// are not the blocks' (an invocation a block). Each pixel belongs to the one block whose
// half-open square holds it, and that block lists it: its centre where it was refined, the
// midpoints of its top and left edges where it or the block across that edge was, and those of
// its bottom and right edges where no block lies beyond them (the image's last row or column)
// and it was refined. So each midpoint is listed once, and a block interpolated at level 0
// beside a refined one gets the traced midpoint on their shared edge.
@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn midpoints(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let b = id.xy;
    // The centre, the top, left, bottom and right midpoints, and whether each is listed.
    var points: array<vec2<u32>, 5>;
    var picks = array<bool, 5>();
    if all(b < adaptive.blocks) {
        let first = b * ADAPTIVE_BLOCK;
        let far = min(first + ADAPTIVE_BLOCK, size() - 1u);
        let mid = first + ADAPTIVE_BLOCK / 2u;
        let has = mid < far;
        let refined = refined_at(b);
        let up = refined || (b.y > 0u && refined_at(b - vec2<u32>(0u, 1u)));
        let left = refined || (b.x > 0u && refined_at(b - vec2<u32>(1u, 0u)));
        // No block beyond: this block's square reaches the image's last row or column.
        let last = (first + ADAPTIVE_BLOCK >= size()) & (far > first);
        points = array(mid, vec2(mid.x, first.y), vec2(first.x, mid.y), vec2(mid.x, far.y),
            vec2(far.x, mid.y));
        picks = array(refined && all(has), has.x && up, has.y && left,
            has.x && refined && last.y, has.y && refined && last.x);
    }
    var n = 0u;
    for (var i = 0u; i < 5u; i++) {
        n += select(0u, 1u, picks[i]);
    }
    var slot = reserve(n, local);
    for (var i = 0u; i < 5u; i++) {
        if picks[i] {
            atomicStore(&work[slot], index_of(points[i]));
            slot++;
        }
    }
}

// The second difference of displayed colours `before`, `c`, `after` at `c` (see `bend`); the
// first difference where only one neighbour exists (`has`), 0 where none does.
fn curvature(before: vec3<f32>, c: vec3<f32>, after: vec3<f32>, has: vec2<bool>) -> f32 {
    if all(has) {
        return largest(abs(before - 2.0 * c + after));
    }
    if has.x {
        return largest(abs(c - before));
    }
    if has.y {
        return largest(abs(after - c));
    }
    return 0.0;
}

// What `select_pixels` reads around its workgroup's pixels (WORKGROUP_2D rows of WORKGROUP_2D
// strips, and the ring of pixels around them), loaded once into workgroup memory: each pixel's
// displayed colour (`shown`), and in w whether the lens masks it (SEEN_MASKED), it is
// interpolated (SEEN_UNTRACED) or traced (SEEN_TRACED). A pixel is read by itself and its four
// neighbours: loading it once displays its colour once instead of five times (on lavapipe,
// whose SIMD lanes run a whole row of strips wherever one pixel of it was traced, for every
// pixel).
const PIXEL_TILE_X: u32 = WORKGROUP_2D * ADAPTIVE_STRIP + 2u;
const PIXEL_TILE_Y: u32 = WORKGROUP_2D + 2u;
const SEEN_MASKED: f32 = 0.0;
const SEEN_UNTRACED: f32 = 1.0;
const SEEN_TRACED: f32 = 2.0;
var<workgroup> pixel_tile: array<vec4<f32>, PIXEL_TILE_X * PIXEL_TILE_Y>;
// Beside each, whether its radiance runs past the display's range (a channel above 1).
var<workgroup> pixel_over: array<u32, PIXEL_TILE_X * PIXEL_TILE_Y>;

// Loads the pixel tile of the workgroup whose first pixel is `origin` (every invocation calls
// it, in uniform control flow: it has a barrier). Entries outside the image are left as they
// are: nothing reads them.
fn load_pixel_tile(origin: vec2<u32>, local: u32) {
    for (var t = local; t < PIXEL_TILE_X * PIXEL_TILE_Y; t += WORKGROUP_2D * WORKGROUP_2D) {
        let q = vec2<i32>(origin) - 1 + vec2<i32>(i32(t % PIXEL_TILE_X), i32(t / PIXEL_TILE_X));
        if any(q < vec2<i32>(0)) || any(q >= vec2<i32>(size())) {
            continue;
        }
        let i = index_of(vec2<u32>(q));
        let key = key_at(i);
        var seen = SEEN_TRACED;
        if key == KEY_MASKED {
            seen = SEEN_MASKED;
        } else if key == KEY_UNTRACED {
            seen = SEEN_UNTRACED;
        }
        let c = colour_out[i].rgb;
        pixel_tile[t] = vec4<f32>(shown(c), seen);
        pixel_over[t] = select(0u, 1u, largest(c) > 1.0);
    }
    workgroupBarrier();
}

// Pixel `p`'s place in the pixel tile of the workgroup whose first pixel is `origin`.
fn pixel_slot(origin: vec2<u32>, p: vec2<u32>) -> u32 {
    let t = p + 1u - origin;
    return t.y * PIXEL_TILE_X + t.x;
}

// Pixel `p`'s entry in the pixel tile of the workgroup whose first pixel is `origin`.
fn pixel_seen(origin: vec2<u32>, p: vec2<u32>) -> vec4<f32> {
    return pixel_tile[pixel_slot(origin, p)];
}

// Whether a neighbour of pixel `p` (in the image) is brighter than the display shows. There
// the 2 × 2 estimating samples cannot bound the pixel's error: displayed colour is clamped,
// the box filter is not, and a sliver of the neighbour's radiance that all four miss can
// outweigh the rest of the pixel (measured: the Cornell box's ceiling around its lamp, where
// four samples on the lamp's thin shadow stopped at 0.2 against a box average past 1; 86 %
// of `auto:0.02`'s MSE through the 180° lens).
fn beside_overexposed(origin: vec2<u32>, p: vec2<u32>) -> bool {
    let q = vec2<i32>(p);
    let last = vec2<i32>(size()) - 1;
    var over = 0u;
    for (var k = 0u; k < 4u; k++) {
        let n = q + vec2<i32>(i32(k == 1u) - i32(k == 0u), i32(k == 3u) - i32(k == 2u));
        if all(n >= vec2<i32>(0)) && all(n <= last) {
            over |= pixel_over[pixel_slot(origin, vec2<u32>(n))];
        }
    }
    return over != 0u;
}

// Whether pixel `p` is supersampled: traced, and its displayed colour bends across it (the
// second difference with its neighbours along either axis, see `bend`) by the threshold or
// more (a one-ray pixel is its box filter's value where the colour changes linearly across
// it), or on the lens's edge (a neighbour masked and it not, or the other way round). Reads
// the pixel tile of the workgroup at `origin`.
fn bends(origin: vec2<u32>, p: vec2<u32>) -> bool {
    let c = pixel_seen(origin, p);
    if c.w == SEEN_UNTRACED {
        return false;
    }
    let last = size() - 1u;
    let has = vec4<bool>(p.x > 0u, (p.x < last.x), p.y > 0u, (p.y < last.y));
    // A neighbour beyond the image's edge stands in as the pixel itself: no bend, no edge.
    let x = vec2<u32>(1u, 0u);
    let y = vec2<u32>(0u, 1u);
    let left = pixel_seen(origin, select(p, p - x, has.x));
    let right = pixel_seen(origin, select(p, p + x, has.y));
    let up = pixel_seen(origin, select(p, p - y, has.z));
    let down = pixel_seen(origin, select(p, p + y, has.w));
    let across = curvature(left.rgb, c.rgb, right.rgb, has.xy);
    let along = curvature(up.rgb, c.rgb, down.rgb, has.zw);
    let masked = c.w == SEEN_MASKED;
    let edge = vec4<f32>(left.w, right.w, up.w, down.w) == vec4<f32>(SEEN_MASKED);
    return max(across, along) >= adaptive.threshold || any(edge != vec4<bool>(masked));
}

// Pixel `k` of the strip that invocation `id` of a per-pixel listing kernel looks at:
// ADAPTIVE_STRIP pixels side by side in a row.
fn strip_pixel(id: vec3<u32>, k: u32) -> vec2<u32> {
    return vec2<u32>(id.x * ADAPTIVE_STRIP + k, id.y);
}

// Lists the pixels of invocation `id`'s strip that `picks` marks (`reserve`'s rules: every
// invocation calls it).
fn list_strip(id: vec3<u32>, picks: array<bool, ADAPTIVE_STRIP>, local: u32) {
    var n = 0u;
    for (var k = 0u; k < ADAPTIVE_STRIP; k++) {
        n += select(0u, 1u, picks[k]);
    }
    var slot = reserve(n, local);
    for (var k = 0u; k < ADAPTIVE_STRIP; k++) {
        if picks[k] {
            atomicStore(&work[slot], index_of(strip_pixel(id, k)));
            slot++;
        }
    }
}

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn select_pixels(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let origin = vec2<u32>(group.x * WORKGROUP_2D * ADAPTIVE_STRIP, group.y * WORKGROUP_2D);
    load_pixel_tile(origin, local);
    // Whether the estimating stage runs (else every pixel listed takes every sample).
    let estimates = SAMPLES_PER_SIDE > ADAPTIVE_ESTIMATE_SIDE && adaptive.threshold > 0.0;
    var picks: array<bool, ADAPTIVE_STRIP>;
    for (var k = 0u; k < ADAPTIVE_STRIP; k++) {
        let p = strip_pixel(id, k);
        picks[k] = all(p < size()) && bends(origin, p);
        // Its neighbours' keys read alike before and after (traced): no race to the image.
        if picks[k] && estimates && beside_overexposed(origin, p) {
            set_key(index_of(p), ADAPTIVE_KEY_MORE);
        }
    }
    list_strip(id, picks, local);
}

// Which pixels of invocation `id`'s strip have the state `key`.
fn keyed(id: vec3<u32>, key: u32) -> array<bool, ADAPTIVE_STRIP> {
    var picks: array<bool, ADAPTIVE_STRIP>;
    for (var k = 0u; k < ADAPTIVE_STRIP; k++) {
        let p = strip_pixel(id, k);
        picks[k] = all(p < size()) && key_at(index_of(p)) == key;
    }
    return picks;
}

// Whether pixel `p` took the 2 × 2 estimating samples: its colour is theirs, so supersampling
// can go on from them (a pixel traced at its centre alone took one ray).
fn estimated(p: vec2<u32>) -> bool {
    return atomicLoad(&work[state_slot(index_of(p))]) > 1u;
}

// Pixel `p`'s centre as a corner of `same_surface`'s, its key left out: its ray's hit (normal
// and range) and where that is.
fn centre_corner(p: vec2<u32>) -> Corner {
    let g = geometry_out[index_of(p)];
    return Corner(0u, g, centre_hit(p, g));
}

// Whether traced pixel `p`'s neighbour `offset` away (one pixel along an axis) is in the
// image, demands every sample, and its centre sees another surface than `p`'s: one sees the
// sky and the other not, or their normals or a depth step tell them apart (`same_surface`;
// the material cannot be compared, the neighbour's key no longer says it).
fn demanding_across(p: vec2<u32>, offset: vec2<i32>) -> bool {
    let q = vec2<i32>(p) + offset;
    let inside = all(q >= vec2<i32>(0)) && all(q < vec2<i32>(size()));
    if !inside || key_at(index_of(vec2<u32>(q))) != ADAPTIVE_KEY_MORE {
        return false;
    }
    let a = centre_corner(p);
    let b = centre_corner(vec2<u32>(q));
    if a.geometry.w == 0.0 || b.geometry.w == 0.0 {
        return (a.geometry.w == 0.0) != (b.geometry.w == 0.0);
    }
    return !same_surface(a, b);
}

// Lists the pixels to supersample: those that demand every sample (ADAPTIVE_KEY_MORE), and
// each other estimated pixel beside one of them (left, right, above or below) across a change
// of surface.
//
// Two samples a half say little: an edge that crosses a pixel can miss both halves' samples
// alike, and where it crosses one pixel it runs on into the next. So an estimated pixel whose
// neighbour demands more and sees another surface takes every sample too, as Cycles'
// adaptive sampling dilates its unconverged pixels into their neighbours
// (`film_adaptive_sampling_filter_x` and `_y`). Only across a change of surface: within one,
// the neighbour's demand is the detail of its own texture or lighting, which the pixel's own
// estimate judged (dilating there too cost Šibenik many rays for little).
@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn more(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    var picks = keyed(id, ADAPTIVE_KEY_MORE);
    for (var k = 0u; k < ADAPTIVE_STRIP; k++) {
        let p = strip_pixel(id, k);
        if !picks[k] && all(p < size()) && estimated(p) {
            picks[k] = demanding_across(p, vec2<i32>(-1, 0)) || demanding_across(p, vec2<i32>(1, 0))
                || demanding_across(p, vec2<i32>(0, -1)) || demanding_across(p, vec2<i32>(0, 1));
        }
    }
    list_strip(id, picks, local);
}

@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn untraced(@builtin(global_invocation_id) id: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    list_strip(id, keyed(id, KEY_UNTRACED), local);
}
