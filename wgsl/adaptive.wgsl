// Adaptive sampling: rays where the picture needs them, every pass on the GPU. The image is
// covered by blocks of ADAPTIVE_BLOCK × ADAPTIVE_BLOCK pixels whose corners form a lattice of
// pixel centres (the last row and column of the image are lattice points too), each block by
// four half-blocks, whose corners form a lattice twice as fine:
//
// 1. `trace_list` traces one shaded ray through each lattice pixel's centre (a first pass
//    below one ray per pixel: 1/ADAPTIVE_BLOCK² of them), an invocation a lattice point, with
//    no list (MODE_LATTICE; or through every pixel's, MODE_EVERY_PIXEL, and the frame goes on
//    at step 4);
// 2. `classify` looks at each block's four corners (Whitted 1980 subdivided a pixel whose
//    corners disagree): where they agree (the same surface, normals and tangent planes, and
//    displayed colour along each edge that bends by less than the threshold, see `bend`), the
//    lattice points beyond them along its edges see what they see (`ring_agrees`: no
//    silhouette curves in between) and the lens covers every pixel, the block's other pixels
//    are interpolated between the corners in linear radiance, bicubically (Catmull-Rom
//    splines through the corners and the ring of lattice points beyond them, a point of the
//    ring on another surface replaced by a line: `spline_points`, `catmull_rom`), so no
//    interpolation crosses a change of surface or a depth step. `midpoints` (in
//    `adaptive_lists.wgsl`) lists the half-blocks' corners in the other blocks, the midpoints
//    of their edges and their centres, and `trace_list` traces them;
// 3. `classify` at level 1 does the same for the half-blocks of those blocks (interpolating
//    bilinearly), and the pixels of the half-blocks whose corners disagree are listed and
//    traced (at one ray a pixel at most, but for those between two of their corners that
//    agree, interpolated between them: `on_agreeing_edge`): rays subdivide where the image
//    changes, as Painter and Sloan (1989) and Thomas, Netravali and Fox (1989) refined a
//    coarse sampling level by level, so an edge takes a band of rays half a block wide, and
//    a block whose colour bends only at its own scale is interpolated from its half-blocks;
// 4. `select_pixels` (in `adaptive_lists.wgsl`, with `more` and `untraced`) lists the pixels
//    traced whose displayed colour bends across them (the second difference with their
//    neighbours, along either axis) by the threshold or more, and those on the lens's edge: a
//    one-ray pixel is its box filter's value where colour changes linearly across it, and the
//    bend estimates how far off it is (Mitchell 1987 drove supersampling by such local
//    contrast). Where SAMPLES_PER_SIDE > 2 and the threshold is
//    above 0, `trace_samples` (in `adaptive_samples.wgsl`) first takes 2 × 2 stratified
//    samples of each (`MODE_ESTIMATE`) and marks those whose half-sample mean differs from
//    the mean by the threshold or more (Dammertz et al. 2010's error estimate); `more` lists
//    those, and the estimated pixels beside them across a change of surface. The last list's
//    pixels take the SAMPLES_PER_SIDE² samples that uniform
//    supersampling takes (`sample_offset`), in its order (`trace_samples` again), going on
//    from the estimate's where those are the first of them (the nested 4 × 4 pattern);
// 5. with ground truth asked for, `untraced` lists the interpolated pixels and `trace_list`
//    traces their centres' first hits, so ids, normals and ranges are never interpolated.
//
// The later stages' lists are compacted by one atomic per workgroup; `adaptive_args.wgsl`
// turns a list's length into the indirect dispatch of `trace_list` or `trace_samples`; nothing
// is read back between passes. A pixel's result depends on its own samples and its
// neighbours' alone, so the order in which lists fill does not change the image: reruns are
// bit-identical.
#import pixel
#import colour
#import interpolate

// Mirrors `fisheye_rt::shared::AdaptiveParams`.
struct AdaptiveParams {
    // Displayed-colour difference (clamped sRGB, largest channel) at which two samples
    // disagree; 0 traces every pixel with every sample.
    threshold: f32,
    // The least cosine between two corners' shading normals on one smooth surface.
    normal_cosine: f32,
    // The farthest a corner's hit may lie from another corner's tangent plane, relative to
    // the larger range.
    plane_distance: f32,
    _pad0: u32,
    // Lattice points across and down: the blocks' corners.
    lattice: vec2<u32>,
    // Blocks across and down.
    blocks: vec2<u32>,
    // The half-blocks' corners across and down (a lattice twice as fine).
    half_lattice: vec2<u32>,
    // Half-blocks across and down.
    halves: vec2<u32>,
}

// The list's length (ADAPTIVE_COUNT) and the part of it to trace (ADAPTIVE_FIRST to
// ADAPTIVE_END, set by `adaptive_args.wgsl`), then the list of pixel indices from
// ADAPTIVE_HEADER on (room for every pixel), then each pixel's state (`state_slot`), then each
// block's decision (`block_slot`). One buffer, so that the kernels bind as few storage
// buffers as WebGPU's default allows.
@group(0) @binding(7) var<storage, read_write> work: array<atomic<u32>>;
@group(0) @binding(8) var<uniform> adaptive: AdaptiveParams;

// What is traced of the pixels listed (MODE_*, `fisheye_rt::shared`): centres and first hits
// by `trace_list`, a pipeline for each (the first-hit kernel is the smaller: one kernel
// holding both would be as slow as the larger), whose centres' pipeline also traces the
// coarse stage's points (ADAPTIVE_MODE: MODE_LATTICE, MODE_EVERY_PIXEL); samples and
// estimates by `trace_samples`, a pipeline for each too (one kernel for both, the mode read at
// run time, took about a tenth longer a sample on lavapipe: its samples a side, the bounds of
// its loops and divisors of its strata, were no longer constants, and it needed a barrier).
override LIST_MODE: u32 = MODE_CENTRE;
// The level `classify` decides at: 0, the blocks (ADAPTIVE_BLOCK pixels a side, whose corners
// the coarse stage traced); 1, the half-blocks of the blocks refined at level 0 (whose corners
// the midpoint stage added). The lattice kernels read it too (level 0: the blocks' corners).
override LEVEL: u32 = 0u;
// What a pixel's centre saw: not traced (interpolated), masked by the lens, nothing (sky);
// else the material and instance hit (`surface_key`).
const KEY_UNTRACED: u32 = 0xffffffffu;
const KEY_MASKED: u32 = 0xfffffffeu;
const KEY_SKY: u32 = 0xfffffffdu;
// A pixel whose first samples still disagree (`MODE_ESTIMATE`) takes them all: its key is then
// ADAPTIVE_KEY_MORE (`fisheye_rt::shared`, which `AdaptivePass::read_demanding` reads), below
// these three and above every `surface_key`.

var<workgroup> group_count: atomic<u32>;
var<workgroup> group_base: u32;
var<workgroup> group_any: atomic<u32>;
var<workgroup> group_found: u32;

fn size() -> vec2<u32> {
    return vec2<u32>(lens.width, lens.height);
}

fn index_of(p: vec2<u32>) -> u32 {
    return p.y * lens.width + p.x;
}

// Where pixel `index`'s state is in `work`: the rays its colour took (the spp map), then what
// its centre ray saw (KEY_*).
fn state_slot(index: u32) -> u32 {
    return ADAPTIVE_HEADER + lens.width * lens.height + 2u * index;
}

// Where block `b`'s decision is kept in `work`: BLOCK_INTERPOLATED, or where its corners
// disagreed (its half-blocks are decided at level 1) BLOCK_COVERED when no lattice point near
// it is masked (the lens covers all of it, see `masked_near`), else BLOCK_NEAR_EDGE.
fn block_slot(b: vec2<u32>) -> u32 {
    return ADAPTIVE_HEADER + 3u * lens.width * lens.height + b.y * adaptive.blocks.x + b.x;
}

const BLOCK_INTERPOLATED: u32 = 0u;
const BLOCK_COVERED: u32 = 1u;
const BLOCK_NEAR_EDGE: u32 = 2u;

fn block_at(b: vec2<u32>) -> u32 {
    return atomicLoad(&work[block_slot(b)]);
}

fn refined_at(b: vec2<u32>) -> bool {
    return block_at(b) != BLOCK_INTERPOLATED;
}

fn key_at(index: u32) -> u32 {
    return atomicLoad(&work[state_slot(index) + 1u]);
}

fn set_key(index: u32, key: u32) {
    atomicStore(&work[state_slot(index) + 1u], key);
}

fn set_state(index: u32, rays: u32, key: u32) {
    atomicStore(&work[state_slot(index)], rays);
    set_key(index, key);
}

fn add_rays(index: u32, rays: u32) {
    atomicAdd(&work[state_slot(index)], rays);
}

// The material and instance of a primary hit, as one number below the KEY_* values.
fn surface_key(traced: Traced) -> u32 {
    if traced.triangle == NO_HIT {
        return KEY_SKY;
    }
    let material = triangle_at(traced.hit.slot).material & 0xffffu;
    return material | ((traced.hit.instance & 0x3fffu) << 16u);
}

// Reserves `n` list entries for this invocation, with one global atomic per workgroup, and
// returns the first one's place in `work`. Every invocation of the workgroup must call it, in
// uniform control flow (it has barriers).
fn reserve(n: u32, local: u32) -> u32 {
    let mine = atomicAdd(&group_count, n);
    workgroupBarrier();
    if local == 0u {
        group_base = atomicAdd(&work[ADAPTIVE_COUNT], atomicLoad(&group_count));
    }
    return ADAPTIVE_HEADER + workgroupUniformLoad(&group_base) + mine;
}

// Whether `pick` holds for any invocation of the workgroup, as a value uniform across it (every
// invocation must call it, in uniform control flow: it has barriers).
fn any_in_group(pick: bool, local: u32) -> bool {
    if pick {
        atomicStore(&group_any, 1u);
    }
    workgroupBarrier();
    if local == 0u {
        group_found = atomicLoad(&group_any);
    }
    return workgroupUniformLoad(&group_found) == 1u;
}

// The side of LEVEL's blocks, in pixels: the spacing of their lattice.
fn spacing() -> u32 {
    return ADAPTIVE_BLOCK >> LEVEL;
}

// LEVEL's lattice points across and down.
fn level_lattice() -> vec2<u32> {
    return select(adaptive.lattice, adaptive.half_lattice, LEVEL == 1u);
}

// The pixel at LEVEL's lattice point `i`.
fn lattice_pixel(i: vec2<u32>) -> vec2<u32> {
    return min(i * spacing(), size() - 1u);
}

fn is_lattice(p: vec2<u32>) -> bool {
    let last = size() - 1u;
    let s = spacing();
    return (p.x % s == 0u || p.x == last.x) && (p.y % s == 0u || p.y == last.y);
}

// Traces the centre of pixel `index` (at `pixel`) as `mode` says: shaded (MODE_CENTRE), or
// its first hit alone (MODE_TRUTH). Through a prescription's glass, MODE_CENTRE's colour is
// the pixel's one film sample's (`glass_radiance`).
fn trace_centre(index: u32, pixel: vec2<u32>, mode: u32) {
    let ray = primary_ray(pixel);
    if ray.w == 0.0 {
        if mode == MODE_CENTRE {
            colour_out[index] = vec4<f32>(0.0);
            set_state(index, 0u, KEY_MASKED);
        }
        geometry_out[index] = vec4<f32>(0.0);
        ids_out[index] = NO_HIT;
        return;
    }
    if mode == MODE_TRUTH {
        let hit = first_hit(centre_ray(pixel, ray.xyz));
        geometry_out[index] = geometry_of(hit);
        ids_out[index] = hit.triangle;
        return;
    }
    var traced: Traced;
    if GLASS {
        // The ray of the pixel's one film sample through the glass makes the colour, as
        // uniform sampling's at one ray a pixel; the fitted model's centre ray, the ground
        // truth and what the pixel's neighbours compare.
        traced = first_hit(centre_ray(pixel, ray.xyz));
        colour_out[index] = vec4<f32>(glass_radiance(pixel, index, 0u, 1u), 1.0);
    } else {
        traced = shade_centre(pixel, ray.xyz);
        colour_out[index] = vec4<f32>(traced.colour, 1.0);
    }
    geometry_out[index] = geometry_of(traced);
    ids_out[index] = traced.triangle;
    set_state(index, 1u, surface_key(traced));
}

// Traces the centres of list entries ADAPTIVE_FIRST to ADAPTIVE_END as LIST_MODE says
// (`trace_centre`), an invocation each; or (ADAPTIVE_MODE) the coarse stage's points, which
// need no list: the lattice's (MODE_LATTICE) or every pixel's (MODE_EVERY_PIXEL:
// `fisheye_rt::trace::Adaptive::every_pixel`, `--spp auto:T:MAX:1`; then no pixel is
// interpolated, and the frame goes on at step 4), a WORKGROUP_2D² tile of them a workgroup,
// in rows of tiles, as a dispatch over the points in 2D would take them.
@compute @workgroup_size(WORKGROUP_1D)
fn trace_list(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let mode = atomicLoad(&work[ADAPTIVE_MODE]);
    let g = group.y * groups.x + group.x;
    var pixel: vec2<u32>;
    if mode == MODE_LATTICE || mode == MODE_EVERY_PIXEL {
        let every = mode == MODE_EVERY_PIXEL;
        let points = select(adaptive.lattice, size(), every);
        let tiles = (points.x + WORKGROUP_2D - 1u) / WORKGROUP_2D;
        let tile = vec2<u32>(g % tiles, g / tiles);
        let p = tile * WORKGROUP_2D + vec2<u32>(local % WORKGROUP_2D, local / WORKGROUP_2D);
        if any(p >= points) {
            return;
        }
        pixel = select(lattice_pixel(p), p, every);
    } else {
        let i = atomicLoad(&work[ADAPTIVE_FIRST]) + g * WORKGROUP_1D + local;
        if i >= atomicLoad(&work[ADAPTIVE_END]) {
            return;
        }
        let index = atomicLoad(&work[ADAPTIVE_HEADER + i]);
        pixel = vec2<u32>(index % lens.width, index / lens.width);
    }
    trace_centre(index_of(pixel), pixel, LIST_MODE);
}

// What a block's corner saw: its key, and its hit's normal and position (relative to the
// scene's origin; only where it hit a surface, the one case `same_surface` reads it).
struct Corner {
    key: u32,
    geometry: vec4<f32>,
    position: vec3<f32>,
}

// Where pixel `p`'s centre ray, whose hit is `geometry` (normal and range), meets the surface
// (relative to the scene's origin).
fn centre_hit(p: vec2<u32>, geometry: vec4<f32>) -> vec3<f32> {
    let ray = centre_ray(p, primary_ray(p).xyz);
    return ray.origin + ray.dir * geometry.w;
}

// What `classify` reads of the lattice points around its workgroup's blocks, loaded once into
// workgroup memory by `load_tile`: the WORKGROUP_2D² blocks' corners and the ring beyond them
// (whose colours `edge_bend` and keys `masked_near` look at), TILE² points in rows. Each
// point is a corner of up to four blocks and on the lines of up to twelve of their edges: it
// is read from the outputs, its colour displayed and its ray made (to place its hit) once
// instead of at each use (measured in the book's Adaptive sampling: a third off the pass
// where every block is tested).
const TILE: u32 = WORKGROUP_2D + 3u;
var<workgroup> tile_corner: array<Corner, TILE * TILE>;
// The point's traced colour (linear) and its displayed colour (`shown`).
var<workgroup> tile_colour: array<vec4<f32>, TILE * TILE>;
var<workgroup> tile_shown: array<vec3<f32>, TILE * TILE>;

// The tile entry of lattice point `l`, for the workgroup whose first block is `origin`.
fn tile_index(origin: vec2<u32>, l: vec2<i32>) -> u32 {
    let t = vec2<u32>(l - vec2<i32>(origin) + 1);
    return t.y * TILE + t.x;
}

// Loads the tile of the workgroup whose first block is `origin` (every invocation calls it,
// in uniform control flow: it has a barrier). Entries outside the lattice are left as they
// are: nothing reads them.
fn load_tile(origin: vec2<u32>, local: u32) {
    let last = vec2<i32>(level_lattice()) - 1;
    for (var t = local; t < TILE * TILE; t += WORKGROUP_2D * WORKGROUP_2D) {
        let l = vec2<i32>(origin) - 1 + vec2<i32>(i32(t % TILE), i32(t / TILE));
        if any(l < vec2<i32>(0)) || any(l > last) {
            continue;
        }
        let p = lattice_pixel(vec2<u32>(l));
        let i = index_of(p);
        let key = key_at(i);
        let g = geometry_out[i];
        var position = vec3<f32>(0.0);
        if key < ADAPTIVE_KEY_MORE {
            position = centre_hit(p, g);
        }
        tile_corner[t] = Corner(key, g, position);
        let c = colour_out[i];
        tile_colour[t] = c;
        tile_shown[t] = shown(c.rgb);
    }
    workgroupBarrier();
}

// Whether two traced, unmasked corners see one smooth stretch of one surface: the same
// material and instance, normals close, and each hit near the other's tangent plane (no depth
// step between them).
fn same_surface(a: Corner, b: Corner) -> bool {
    if a.key != b.key {
        return false;
    }
    if a.key == KEY_SKY {
        return true;
    }
    if dot(a.geometry.xyz, b.geometry.xyz) < adaptive.normal_cosine {
        return false;
    }
    let allowed = adaptive.plane_distance * max(a.geometry.w, b.geometry.w);
    let d = b.position - a.position;
    return abs(dot(a.geometry.xyz, d)) <= allowed && abs(dot(b.geometry.xyz, d)) <= allowed;
}

// Whether a lattice point among the 4 × 4 around the block at lattice point `l` (its corners
// and the ring beyond) is masked: where none is, the lens's edge is more than a block away
// and, the lens's valid region being convex (a disk or ellipse, or the whole image), does not
// cross the block. A point not traced (at level 1, in a block interpolated at level 0) may be
// masked. Reads the tile of the workgroup at `origin`.
fn masked_near(origin: vec2<u32>, l: vec2<u32>) -> bool {
    let first = vec2<i32>(l) - 1;
    let last = vec2<i32>(level_lattice()) - 1;
    for (var y = max(first.y, 0); y <= min(first.y + 3, last.y); y++) {
        for (var x = max(first.x, 0); x <= min(first.x + 3, last.x); x++) {
            let key = tile_corner[tile_index(origin, vec2<i32>(x, y))].key;
            if key == KEY_UNTRACED || key == KEY_MASKED {
                return true;
            }
        }
    }
    return false;
}

// Whether the eight lattice points beside the corners of the block from `l` to `l11`, one
// beyond each corner along each of its edges' lines, see what the corner beside them sees
// (material and instance, or sky: `key`) where they lie in the image. A silhouette that
// passes between a corner and the next point beyond may curve into the block between
// corners that agree; one that passes outside them all is a block or more away.
fn ring_agrees(
    origin: vec2<u32>, l: vec2<i32>, l11: vec2<i32>, a: Corner, b: Corner, c: Corner, d: Corner,
) -> bool {
    let last = vec2<i32>(level_lattice()) - 1;
    let corners = array<vec2<i32>, 4>(l, vec2<i32>(l11.x, l.y), vec2<i32>(l.x, l11.y), l11);
    let keys = vec4<u32>(a.key, b.key, c.key, d.key);
    for (var i = 0u; i < 4u; i++) {
        // Outward from corner i: left or right, then up or down.
        let out = select(vec2<i32>(-1), vec2<i32>(1), vec2<bool>((i & 1u) == 1u, i >= 2u));
        for (var axis = 0u; axis < 2u; axis++) {
            var p = corners[i];
            p[axis] += out[axis];
            let inside = all(p >= vec2<i32>(0)) && all(p <= last);
            if inside && tile_corner[tile_index(origin, p)].key != keys[i] {
                return false;
            }
        }
    }
    return true;
}

// `bend` along the lattice edge from lattice point `a` to its neighbour `b`, from the tile of
// the workgroup at `origin`.
fn edge_bend(origin: vec2<u32>, a: vec2<u32>, b: vec2<u32>) -> f32 {
    let d = vec2<i32>(b) - vec2<i32>(a);
    let before = vec2<i32>(a) - d;
    let after = vec2<i32>(b) + d;
    let last = vec2<i32>(level_lattice()) - 1;
    let ta = tile_index(origin, vec2<i32>(a));
    let tb = tile_index(origin, vec2<i32>(b));
    var has = vec2<bool>(false);
    var cb = vec3<f32>(0.0);
    var ca = vec3<f32>(0.0);
    if all(before >= vec2<i32>(0)) {
        let t = tile_index(origin, before);
        has.x = tile_corner[t].key == tile_corner[ta].key;
        cb = tile_shown[t];
    }
    if all(after <= last) {
        let t = tile_index(origin, after);
        has.y = tile_corner[t].key == tile_corner[tb].key;
        ca = tile_shown[t];
    }
    return bend(cb, tile_shown[ta], tile_shown[tb], ca, has);
}

// Which of the 4 × 4 lattice points around the level-0 block from lattice point `l` to `l11`
// (its corners, and the ring beyond them, in the tile of the workgroup at `origin`) a spline
// may pass through: bit 4y + x. The corners always; a point of the ring where it lies in the
// image, sees the material and instance that the corners see (`key`), and along each axis is
// the block's own or a whole spacing on from the next (the image's last row and column of
// lattice points may lie nearer: along an axis where the block itself is short, only its own).
fn spline_points(origin: vec2<u32>, l: vec2<u32>, l11: vec2<u32>, key: u32) -> u32 {
    let last = vec2<i32>(level_lattice()) - 1;
    let step = i32(spacing());
    let corner = vec2<i32>(lattice_pixel(l));
    let whole = vec2<i32>(lattice_pixel(l11)) - corner == vec2<i32>(step);
    var points = 0u;
    for (var k = 0u; k < 16u; k++) {
        let d = vec2<i32>(i32(k % 4u), i32(k / 4u)) - 1;
        let own = (d == vec2<i32>(0)) | (d == vec2<i32>(1));
        // Along a short axis (the image's last row or column) the far corner is `l11`.
        let q = select(vec2<i32>(l) + d, vec2<i32>(l11) + d - 1, d >= vec2<i32>(1));
        if all(own) {
            points |= 1u << k;
            continue;
        }
        if !all(own | whole) || any(q < vec2<i32>(0)) || any(q > last) {
            continue;
        }
        let even = all(own | (vec2<i32>(lattice_pixel(vec2<u32>(q))) - corner == d * step));
        if even && tile_corner[tile_index(origin, q)].key == key {
            points |= 1u << k;
        }
    }
    return points;
}

// `spline` down column `x` of the 4 × 4 points (`spline_points`: `points`), from tile entries
// `at` and `below` beside the block; its ends are read only where the spline may use them.
fn column(at: u32, below: u32, x: u32, w: vec4<f32>, points: u32) -> vec3<f32> {
    let has = vec2<bool>((points & (1u << x)) != 0u, (points & (1u << (12u + x))) != 0u);
    var a = vec3<f32>(0.0);
    var d = vec3<f32>(0.0);
    if has.x {
        a = tile_colour[at - TILE].rgb;
    }
    if has.y {
        d = tile_colour[below + TILE].rgb;
    }
    return spline(w, a, tile_colour[at].rgb, tile_colour[below].rgb, d, has);
}

// Whether the lens gives a ray to every pixel of the block from `first` to `end` (exclusive),
// or (with `covered` false) to none.
fn block_mask_is(first: vec2<u32>, end: vec2<u32>, covered: bool) -> bool {
    for (var y = first.y; y < end.y; y++) {
        for (var x = first.x; x < end.x; x++) {
            if (primary_ray(vec2<u32>(x, y)).w != 0.0) != covered {
                return false;
            }
        }
    }
    return true;
}

// Whether pixel `p` of the half-block from `first` lies on its top edge and that edge's corners
// agree (`agree.x`), or on its left edge and those corners agree (`agree.y`).
fn on_agreeing_edge(p: vec2<u32>, first: vec2<u32>, agree: vec2<bool>) -> bool {
    return (agree.x && p.y == first.y) || (agree.y && p.x == first.x);
}

// Decides LEVEL's blocks (an invocation a block): where its corners agree (see the file's
// header) the block's other pixels are interpolated between them; else, at level 0, its
// decision is kept for `midpoints` and its half-blocks (its pixels are left to level 1), and
// at level 1 its other pixels are listed for `trace_list`. At level 1 only the half-blocks of
// the blocks refined at level 0 are looked at: the others' pixels are already interpolated.
@compute @workgroup_size(WORKGROUP_2D, WORKGROUP_2D)
fn classify(
    @builtin(global_invocation_id) id: vec3<u32>,
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) local: u32,
) {
    let origin = group.xy * WORKGROUP_2D;
    var inside = all(id.xy < select(adaptive.blocks, adaptive.halves, LEVEL == 1u));
    // At level 1, whether the lens may mask part of the block (its parent's decision);
    // at level 0 the tests find out.
    var near_edge = LEVEL == 0u;
    if LEVEL == 1u {
        var parent = BLOCK_INTERPOLATED;
        if inside {
            parent = block_at(id.xy / 2u);
        }
        inside = parent != BLOCK_INTERPOLATED;
        near_edge = parent == BLOCK_NEAR_EDGE;
        // A workgroup none of whose blocks was refined has nothing to do: it leaves before
        // loading its tile (most of them, where the image is smooth).
        if !any_in_group(inside, local) {
            return;
        }
    }
    load_tile(origin, local);
    let first = id.xy * spacing();
    let end = min(first + spacing(), size());
    let far = min(first + spacing(), size() - 1u);
    // The block's corners, as lattice points: first (l), across, down, and far (l11).
    let l = id.xy;
    let l11 = min(l + 1u, level_lattice() - 1u);
    let l10 = vec2<u32>(l11.x, l.y);
    let l01 = vec2<u32>(l.x, l11.y);
    let t00 = tile_index(origin, vec2<i32>(l));
    let t10 = tile_index(origin, vec2<i32>(l10));
    let t01 = tile_index(origin, vec2<i32>(l01));
    let t11 = tile_index(origin, vec2<i32>(l11));
    var refine = false;
    var listed = 0u;
    // At level 1, whether a refined half-block's top and left edges (the ones whose pixels
    // it holds) join corners that agree (`on_agreeing_edge`).
    var agree = vec2<bool>(false);
    if inside {
        let a = tile_corner[t00];
        let b = tile_corner[t10];
        let c = tile_corner[t01];
        let d = tile_corner[t11];
        let masked = vec4<u32>(a.key, b.key, c.key, d.key) == vec4<u32>(KEY_MASKED);
        // Whether the lens's edge may cross the block (at level 1 only where it may cross
        // the parent).
        let edge_near = near_edge && masked_near(origin, l);
        if all(masked) {
            // Every pixel is looked at: a valid region smaller than a block (a tiny image's
            // circle) may hold no lattice point at all.
            refine = !block_mask_is(first, end, false);
        } else if any(masked) {
            refine = true;
        } else {
            let top = edge_bend(origin, l, l10);
            let left = edge_bend(origin, l, l01);
            let bottom = edge_bend(origin, l01, l11);
            let right = edge_bend(origin, l10, l11);
            refine = max(max(top, bottom), max(left, right)) >= adaptive.threshold;
            // At one ray a pixel at most, a pixel between two corners of a refined half-block
            // that agree is interpolated between them: an edge through the half-block passes
            // between the other two. Where pixels may be supersampled it is traced, as those
            // beside an edge need (their traced colour shows the bend that lists them).
            if LEVEL == 1u && SAMPLES_PER_SIDE == 1u && !edge_near {
                agree = vec2<bool>(
                    top < adaptive.threshold && same_surface(a, b),
                    left < adaptive.threshold && same_surface(a, c),
                );
            }
            if !refine {
                refine = !(same_surface(a, b) && same_surface(a, c) && same_surface(b, d)
                    && same_surface(c, d) && same_surface(a, d) && same_surface(b, c))
                    || (edge_near && !block_mask_is(first, end, true));
            }
            if LEVEL == 0u && !refine {
                refine = !ring_agrees(origin, vec2<i32>(l), vec2<i32>(l11), a, b, c, d);
            }
        }
        if LEVEL == 0u {
            var decided = BLOCK_INTERPOLATED;
            if refine {
                decided = select(BLOCK_COVERED, BLOCK_NEAR_EDGE, edge_near);
            }
            atomicStore(&work[block_slot(l)], decided);
        } else if refine {
            for (var y = first.y; y < end.y; y++) {
                for (var x = first.x; x < end.x; x++) {
                    let p = vec2<u32>(x, y);
                    listed += select(1u, 0u, is_lattice(p) || on_agreeing_edge(p, first, agree));
                }
            }
        }
    }
    var slot = 0u;
    if LEVEL == 1u {
        slot = reserve(listed, local);
    }
    if !inside {
        return;
    }
    let span = vec2<f32>(max(far - first, vec2<u32>(1u)));
    let all_masked = tile_corner[t00].key == KEY_MASKED;
    let interpolated = !refine && !all_masked;
    // Level 1 stays bilinear: a spline there too lowered ꟻLIP by 1-2 % more for a tenth more
    // of the level's time (lavapipe, the Cornell box; most of its rings are interpolated).
    var points = 0u;
    if LEVEL == 0u && interpolated {
        points = spline_points(origin, l, l11, tile_corner[t00].key);
    }
    // The ring's columns either side of the block, where both their points beside it may be
    // used (else the spline across continues the line through the block's columns).
    let sides = vec2<bool>((points & 0x110u) == 0x110u, (points & 0x880u) == 0x880u);
    // The spline is kept within the block's corners' colours, as the bilinear is.
    let c00 = tile_colour[t00].rgb;
    let c10 = tile_colour[t10].rgb;
    let c01 = tile_colour[t01].rgb;
    let c11 = tile_colour[t11].rgb;
    let low = min(min(c00, c10), min(c01, c11));
    let high = max(max(c00, c10), max(c01, c11));
    for (var y = first.y; y < end.y; y++) {
        // The interpolant down each column of lattice points at this row, then across them at
        // each pixel: splines down the four columns (level 0), or lines down the block's sides.
        var down0 = vec3<f32>(0.0);
        var down1 = vec3<f32>(0.0);
        var down2 = vec3<f32>(0.0);
        var down3 = vec3<f32>(0.0);
        let fy = f32(y - first.y) / span.y;
        if LEVEL == 0u && interpolated {
            let w = catmull_rom(fy);
            if sides.x {
                down0 = column(t00 - 1u, t01 - 1u, 0u, w, points);
            }
            down1 = column(t00, t01, 1u, w, points);
            down2 = column(t10, t11, 2u, w, points);
            if sides.y {
                down3 = column(t10 + 1u, t11 + 1u, 3u, w, points);
            }
        } else if interpolated || any(agree) {
            // Lines down the sides; at a refined half-block's agreeing top edge (fy = 0) or
            // left edge (fx = 0) the line between those two corners.
            down1 = mix(c00, c01, fy);
            down2 = mix(c10, c11, fy);
        }
        for (var x = first.x; x < end.x; x++) {
            let p = vec2<u32>(x, y);
            if is_lattice(p) || (refine && LEVEL == 0u) {
                continue;
            }
            let i = index_of(p);
            if refine && !on_agreeing_edge(p, first, agree) {
                atomicStore(&work[slot], i);
                slot += 1u;
                continue;
            }
            geometry_out[i] = vec4<f32>(0.0);
            ids_out[i] = NO_HIT;
            if all_masked {
                colour_out[i] = vec4<f32>(0.0);
                set_state(i, 0u, KEY_MASKED);
                continue;
            }
            let fx = f32(x - first.x) / span.x;
            var c = mix(down1, down2, fx);
            if LEVEL == 0u {
                c = clamp(spline(catmull_rom(fx), down0, down1, down2, down3, sides), low, high);
            }
            colour_out[i] = vec4<f32>(c, 1.0);
            set_state(i, 0u, KEY_UNTRACED);
        }
    }
}
