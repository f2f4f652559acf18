//! Adaptive sampling on planes made for the purpose: a smooth one traced at its block corners
//! only and interpolated bicubically, a straight edge refined only where it crosses, wedges
//! whose tips reach into blocks between corners that see sky, and the estimating stage's
//! pixels on an edge between its samples' columns, on a detail between its samples and beside
//! colours past the display's white.

use super::*;

/// The plane z = 0 from -`half` to `half` in x and y (to 20 at most in y) under one point
/// light (`light`: its position and intensity, TOML), black ambient and sky, seen from
/// `camera` (its position and look-at point, TOML), through the scene loader. With `split`,
/// its halves x < 0 and x > 0 are of two materials (diffuse 0.8 and 0.5).
fn lit_plane(tag: &str, half: f64, camera: &str, light: &str, split: bool) -> Scene {
    let far = half.min(20.0);
    let (obj, mtl) = if split {
        let obj = format!(
            "mtllib plane.mtl\nv -{half} -{half} 0\nv 0 -{half} 0\nv 0 {far} 0\nv -{half} {far} 0\n\
             v {half} -{half} 0\nv {half} {far} 0\nusemtl light\nf 1 2 3\nf 1 3 4\n\
             usemtl dark\nf 2 5 6\nf 2 6 3\n"
        );
        let mtl = "newmtl light\nKd 0.8 0.8 0.8\nnewmtl dark\nKd 0.5 0.5 0.5\n";
        (obj, Some(mtl))
    } else {
        let obj = format!(
            "v -{half} -{half} 0\nv {half} -{half} 0\nv {half} {far} 0\nv -{half} {far} 0\n\
             f 1 2 3\nf 1 3 4\n"
        );
        (obj, None)
    };
    lit_mesh(tag, &obj, mtl, camera, light)
}

/// The mesh `obj` (OBJ text; its materials `mtl`, as `plane.mtl`) under one point light, black
/// ambient and sky, seen from `camera`, through the scene loader (as [`lit_plane`]).
fn lit_mesh(tag: &str, obj: &str, mtl: Option<&str>, camera: &str, light: &str) -> Scene {
    let dir = std::env::temp_dir().join(format!("fisheye-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    if let Some(mtl) = mtl {
        std::fs::write(dir.join("plane.mtl"), mtl).unwrap();
    }
    std::fs::write(dir.join("plane.obj"), obj).unwrap();
    std::fs::write(
        dir.join("plane.toml"),
        format!(
            "ambient = [0.0, 0.0, 0.0]\nsky = [0.0, 0.0, 0.0]\n[camera]\n{camera}\n[[mesh]]\n\
             path = \"plane.obj\"\n[[light]]\ntype = \"point\"\n{light}\n"
        ),
    )
    .unwrap();
    let scene = fisheye_rt::scene::load(dir.join("plane.toml").to_str().unwrap())
        .unwrap()
        .scene;
    std::fs::remove_dir_all(&dir).unwrap();
    scene
}

/// The lattice points one beyond each corner of the block from `(x0, y0)` to `(x1, y1)` along
/// its edges' lines, where they lie in an image of `(w, h)` pixels (whose last row and column
/// are on the lattice): those `ring_agrees` in `wgsl/adaptive.wgsl` compares with the corners.
fn beside_corners(
    (x0, y0): (usize, usize),
    (x1, y1): (usize, usize),
    (w, h): (usize, usize),
) -> Vec<(usize, usize)> {
    let block = ADAPTIVE_BLOCK as usize;
    let before = |v: usize| v.checked_sub(block);
    let after = |v: usize, n: usize| (v < n - 1).then(|| (v + block).min(n - 1));
    [
        (before(x0), Some(y0)),
        (Some(x0), before(y0)),
        (after(x1, w), Some(y0)),
        (Some(x1), before(y0)),
        (before(x0), Some(y1)),
        (Some(x0), after(y1, h)),
        (after(x1, w), Some(y1)),
        (Some(x1), after(y1, h)),
    ]
    .into_iter()
    .filter_map(|(x, y)| x.zip(y))
    .collect()
}

/// A plane lit by a distant point light fills a pinhole's view: no edges, colour changing smoothly.
/// Only the lattice of block corners is traced, and bilinear interpolation between them stays
/// within a quarter of the threshold of the one-ray image in displayed colour: the blocks are
/// kept only where the colour bends by less than the threshold along their edges (second
/// differences h²f'' below it), and linear interpolation is off by at most h² max|f''| / 8 on
/// each axis.
#[test]
fn a_smooth_scene_is_traced_at_block_corners_only() {
    let plane = lit_plane(
        "smooth",
        20.0,
        "position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]",
        "position = [10.0, 6.0, 40.0]\nintensity = [1200.0, 1200.0, 1200.0]",
        false,
    );
    let gpu = upload(&plane);
    let (w, h) = (65, 49);
    let cam = camera("rectilinear:f=1", w, h);
    let one = uniform(&gpu, &cam, 1);
    assert!(
        one.ids.iter().all(|&id| id != NO_HIT),
        "the plane fills the view"
    );
    let threshold = 0.02;
    let (out, rays, stages) = adaptive_stages(&gpu, &cam, 16, threshold, false);
    let lattice = |n: u32| (n - 1).div_ceil(ADAPTIVE_BLOCK) + 1;
    let corners = (lattice(w) * lattice(h)) as usize;
    let c = corners as u64;
    let none = [
        Stage::Midpoints,
        Stage::Refine,
        Stage::Estimate,
        Stage::Supersample,
    ]
    .map(|s| (s, 0));
    assert_eq!(stages, [[(Stage::Coarse, c)].as_slice(), &none].concat());
    assert_eq!(
        rays.iter().filter(|&&n| n == 1).count(),
        corners,
        "{rays:?}"
    );
    assert_eq!(
        rays.iter().filter(|&&n| n == 0).count(),
        rays.len() - corners
    );
    // The traced pixels are those `AdaptivePass::coarse_pixels` names (by which `bench`
    // counts the coarse stage's rays): its Rust lattice is the kernel's.
    let options = Adaptive {
        threshold,
        ground_truth: false,
        every_pixel: false,
    };
    let source = DirectionSource::Computed;
    let lanes = SampleLanes::PerPixel;
    let pass = AdaptivePass::with_lanes(ctx(), &cam, &gpu, source, 16, options, lanes).unwrap();
    let named: Vec<usize> = pass
        .coarse_pixels()
        .map(|[x, y]| (y * w + x) as usize)
        .collect();
    let traced: Vec<usize> = (0..rays.len()).filter(|&i| rays[i] == 1).collect();
    assert_eq!(named, traced);
    let shown = |c: f32| linear_to_srgb(c.clamp(0.0, 1.0));
    let worst = one
        .colour
        .iter()
        .zip(&out.colour)
        .flat_map(|(a, b)| (0..3).map(move |k| (shown(a[k]) - shown(b[k])).abs()))
        .fold(0.0f32, f32::max);
    assert!(
        worst <= threshold / 4.0,
        "interpolated {worst} from the one-ray image"
    );
    assert!(
        worst > 0.0,
        "pixels between corners were interpolated, not traced"
    );
}

/// A plane under a nearer light, whose falloff bends the colour within a block, its halves
/// either side of a line at an angle of two materials, at threshold 1 (no colour test: every
/// block whose corners, and the lattice points beside them along its edges, see one material
/// is interpolated): each such block takes the bicubic through its 4 × 4 lattice
/// points (Catmull-Rom splines down the columns, then across; kept within its corners'
/// colours), where a point of its ring sees the other material, lies outside the image or not
/// a whole spacing on (the width, 67, puts the last lattice column 2 pixels from the one
/// before) the line through the block's own points continued instead, and a block shorter than
/// the spacing none of its ring along that axis: as computed here in f64 from the one-ray
/// image's lattice pixels. And where the whole ring is there, the bicubic is nearer the one-ray
/// image than the bilinear through the same corners would be.
#[test]
fn smooth_blocks_are_interpolated_bicubically() {
    // The square z = 0 from -20 to 20, its halves either side of the diagonal y = x of two
    // materials, so that the line between them crosses the image at an angle.
    let plane = lit_mesh(
        "bicubic",
        "mtllib plane.mtl\nv -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\n\
         usemtl light\nf 1 3 4\nusemtl dark\nf 1 2 3\n",
        Some("newmtl light\nKd 0.8 0.8 0.8\nnewmtl dark\nKd 0.5 0.5 0.5\n"),
        "position = [0.3, 0.0, 3.0]\nlook_at = [0.3, 0.0, 0.0]",
        "position = [1.0, 0.5, 1.5]\nintensity = [6.0, 6.0, 6.0]",
    );
    let gpu = upload(&plane);
    let (w, h) = (67usize, 49usize);
    let cam = camera("rectilinear:f=1", w as u32, h as u32);
    let one = uniform(&gpu, &cam, 1);
    let (out, rays) = adaptive(&gpu, &cam, 1, 1.0, false);
    // The first triangle is the light half.
    let light = |x: usize, y: usize| one.ids[y * w + x] == 0;
    assert!(one.ids.iter().all(|&id| id < 2), "the plane fills the view");
    let block = ADAPTIVE_BLOCK as usize;
    // Catmull-Rom weights of the points at -1, 0, 1, 2 at t in [0, 1] (Keys 1981, a = -1/2).
    let weights = |t: f64| {
        [
            (-t * t * t + 2.0 * t * t - t) / 2.0,
            (3.0 * t * t * t - 5.0 * t * t + 2.0) / 2.0,
            (-3.0 * t * t * t + 4.0 * t * t + t) / 2.0,
            (t * t * t - t * t) / 2.0,
        ]
    };
    // The spline through four points, an end that is not there (None) replaced by the line
    // through the middle two continued.
    let spline = |t: f64, p: [Option<f64>; 4]| {
        let (b, c) = (p[1].unwrap(), p[2].unwrap());
        let ends = [p[0].unwrap_or(2.0 * b - c), p[3].unwrap_or(2.0 * c - b)];
        let w = weights(t);
        w[0] * ends[0] + w[1] * b + w[2] * c + w[3] * ends[1]
    };
    // A block's lattice coordinates along an axis of `n` pixels: from `first` to its far
    // corner (the image's last pixel where it is nearer than a block), then the points either
    // side, where they are in the image, on the lattice and a whole block on, and the block
    // itself is whole.
    let points = |first: usize, n: usize| -> [Option<usize>; 4] {
        let far = (first + block).min(n - 1);
        let whole = far - first == block;
        let ring = |q: Option<usize>| q.filter(|&q| whole && q < n && q.is_multiple_of(block));
        [
            ring(first.checked_sub(block)),
            Some(first),
            Some(far),
            ring(Some(far + block)),
        ]
    };
    let is_lattice = |v: usize, n: usize| v.is_multiple_of(block) || v == n - 1;
    let (mut whole, mut partial, mut across) = (0, 0, 0);
    let (mut cubic_error, mut linear_error) = (0.0f64, 0.0f64);
    for y0 in (0..h).step_by(block) {
        for x0 in (0..w).step_by(block) {
            let (columns, rows) = (points(x0, w), points(y0, h));
            let (x1, y1) = (columns[2].unwrap(), rows[2].unwrap());
            let corners = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
            let material = light(x0, y0);
            let beside = beside_corners((x0, y0), (x1, y1), (w, h));
            let differs = |&(x, y): &(usize, usize)| light(x, y) != material;
            if corners.iter().any(differs) || beside.iter().any(differs) {
                continue; // refined: its pixels are the half-blocks' (level 1)
            }
            // Ring point (a, b) of the 4 × 4, where the spline may pass through it.
            let at = |a: usize, b: usize| -> Option<(usize, usize)> {
                let (x, y) = (columns[a]?, rows[b]?);
                let own = (1..3).contains(&a) && (1..3).contains(&b);
                (own || light(x, y) == material).then_some((x, y))
            };
            let ring = (0..16).all(|k| at(k % 4, k / 4).is_some());
            let other = (0..16).any(|k| {
                let (x, y) = (columns[k % 4], rows[k / 4]);
                x.zip(y).is_some_and(|(x, y)| light(x, y) != material)
            });
            for y in y0..(y0 + block).min(h) {
                for x in x0..(x0 + block).min(w) {
                    let p = y * w + x;
                    if rays[p] == 1 {
                        // A lattice point, or a midpoint traced for the refined block beside.
                        assert!(
                            is_lattice(x, w) && is_lattice(y, h)
                                || x == x0 + block / 2
                                || y == y0 + block / 2
                        );
                        assert_eq!(out.colour[p], one.colour[p], "traced pixel ({x}, {y})");
                        continue;
                    }
                    assert_eq!(rays[p], 0, "pixel ({x}, {y}) interpolated");
                    let u = (x - x0) as f64 / (x1 - x0).max(1) as f64;
                    let v = (y - y0) as f64 / (y1 - y0).max(1) as f64;
                    for k in 0..3 {
                        let colour = |(x, y): (usize, usize)| f64::from(one.colour[y * w + x][k]);
                        // Down each column whose points beside the block may be used.
                        let down: [Option<f64>; 4] = std::array::from_fn(|a| {
                            at(a, 1)?;
                            at(a, 2)?;
                            Some(spline(v, std::array::from_fn(|b| at(a, b).map(colour))))
                        });
                        let corners = corners.map(colour);
                        let low = corners.iter().copied().fold(f64::INFINITY, f64::min);
                        let high = corners.iter().copied().fold(0.0, f64::max);
                        let expected = spline(u, down).clamp(low, high);
                        let got = f64::from(out.colour[p][k]);
                        assert!(
                            (got - expected).abs() <= 1e-5 * expected.max(1.0),
                            "pixel ({x}, {y}) channel {k}: {got} against {expected}"
                        );
                        if ring {
                            let linear = (corners[0] * (1.0 - u) + corners[1] * u) * (1.0 - v)
                                + (corners[2] * (1.0 - u) + corners[3] * u) * v;
                            let traced = colour((x, y));
                            cubic_error = cubic_error.max((got - traced).abs());
                            linear_error = linear_error.max((linear - traced).abs());
                        }
                    }
                    if ring {
                        whole += 1
                    } else {
                        partial += 1
                    }
                    if other {
                        across += 1
                    }
                }
            }
        }
    }
    assert!(
        whole > 1000 && partial > 300 && across > 100,
        "{whole} pixels in blocks with their whole ring, {partial} in others, {across} in \
         blocks whose ring sees the other material"
    );
    assert!(
        cubic_error < 0.5 * linear_error,
        "bicubic off the one-ray image by {cubic_error}, bilinear by {linear_error}"
    );
}

/// A plane's straight far edge against the sky: the blocks it crosses (their corners
/// disagree) get their midpoints traced, and within them only the half-blocks it crosses get
/// rays; the half-blocks beside it, on the plane or in the sky, are interpolated (a straight
/// edge that crosses a square separates its corners, so every half-block it crosses is in a
/// refined block). In a half-block it crosses, the pixels between two corners that both see
/// the plane or both the sky are interpolated between them, the others traced. Judged from
/// uniform sampling's hits.
#[test]
fn only_the_pixels_between_disagreeing_corners_are_traced() {
    // Wide enough that its sides are out of view: the one edge seen is its far one, at y = 20.
    let plane = lit_plane(
        "halves",
        1000.0,
        "position = [0.0, -19.0, 1.5]\nlook_at = [6.0, 0.0, 1.0]",
        "position = [10.0, 6.0, 400.0]\nintensity = [90000.0, 90000.0, 90000.0]",
        false,
    );
    let gpu = upload(&plane);
    let (w, h) = (65u32, 49u32);
    let cam = camera("rectilinear:f=1", w, h);
    let one = uniform(&gpu, &cam, 1);
    let (_, rays) = adaptive(&gpu, &cam, 1, 0.02, false);
    let hit = |x: u32, y: u32| one.ids[(y * w + x) as usize] != NO_HIT;
    let half = ADAPTIVE_BLOCK / 2;
    let on = |v: u32, n: u32, step: u32| v.is_multiple_of(step) || v == n - 1;
    let (mut crossed, mut on_agreeing_edges, mut beside) = (0, 0, 0);
    for y in 0..h {
        for x in 0..w {
            if on(x, w, half) && on(y, h, half) {
                continue;
            }
            // The half-block whose half-open square holds the pixel, and its corners.
            let (x0, y0) = (x / half * half, y / half * half);
            let (x1, y1) = ((x0 + half).min(w - 1), (y0 + half).min(h - 1));
            let corners = [hit(x0, y0), hit(x1, y0), hit(x0, y1), hit(x1, y1)];
            let disagree = corners.contains(&true) && corners.contains(&false);
            // A pixel on the half-block's top edge lies between its top corners, one on its
            // left edge between its left ones; any other between all four.
            let between = if y == y0 {
                corners[0] != corners[1]
            } else if x == x0 {
                corners[0] != corners[2]
            } else {
                true
            };
            let n = rays[(y * w + x) as usize];
            assert_eq!(
                n,
                u32::from(disagree && between),
                "pixel ({x}, {y}), corners {corners:?}"
            );
            if disagree && between {
                crossed += 1;
            } else if disagree {
                on_agreeing_edges += 1;
            } else if !(on(x, w, ADAPTIVE_BLOCK) && on(y, h, ADAPTIVE_BLOCK)) {
                beside += 1;
            }
        }
    }
    assert!(
        crossed > 30 && on_agreeing_edges > 15 && beside > 1000,
        "{crossed} crossed, {on_agreeing_edges} on crossed half-blocks' agreeing edges, \
         {beside} beside"
    );
    // Some interpolated pixels lie in blocks the edge crosses (traced whole before).
    let in_crossed_blocks = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            let b = ADAPTIVE_BLOCK;
            let (x0, y0) = (x / b * b, y / b * b);
            let (x1, y1) = ((x0 + b).min(w - 1), (y0 + b).min(h - 1));
            let c = [hit(x0, y0), hit(x1, y0), hit(x0, y1), hit(x1, y1)];
            c.contains(&true) && c.contains(&false) && rays[(y * w + x) as usize] == 0
        })
        .count();
    assert!(
        in_crossed_blocks > 20,
        "{in_crossed_blocks} interpolated in crossed blocks"
    );
}

/// Two materials meet along a line through the centres of a column of pixels (the split
/// plane seen straight down through a pinhole: x = 0 lies on the image's middle column), so
/// each of those pixels' 2 × 2 estimating samples has its left column on one and its right on
/// the other. The half of the strata of one colour of a checkerboard (Dammertz et al.'s
/// interleaved half), like the top row, holds one sample of each: its mean is the pixel's,
/// and alone it would leave the pixel at 4 samples with an error of a quarter of the step.
/// The left column's half is one material: each such pixel takes every sample.
#[test]
fn an_edge_between_the_estimating_samples_columns_is_supersampled() {
    let plane = lit_plane(
        "columns",
        20.0,
        "position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]",
        "position = [10.0, 6.0, 40.0]\nintensity = [1200.0, 1200.0, 1200.0]",
        true,
    );
    let gpu = upload(&plane);
    let (w, h) = (65u32, 49u32);
    let cam = camera("rectilinear:f=1", w, h);
    let (_, rays) = adaptive(&gpu, &cam, 16, 0.02, false);
    let middle = w / 2;
    for y in 0..h {
        assert_eq!(
            rays[(y * w + middle) as usize],
            1 + 16,
            "pixel ({middle}, {y})"
        );
    }
}

/// A dark strip a few hundredths of a pixel wide lies on a lit plane along the centres of a
/// column of pixels (seen straight down through a pinhole, as above): each of those pixels'
/// centre rays sees it, and their 2 × 2 estimating samples, an eighth and three eighths of a
/// pixel either side of the centre, all miss it, so their halves agree. The centre ray, which
/// the estimate weighs beside them, differs from their mean: each such pixel takes every
/// sample (with the halves alone it would stop at 4, the strip missed).
#[test]
fn a_detail_between_the_estimating_samples_is_supersampled() {
    let obj = "mtllib plane.mtl\nv -20 -20 0\nv 20 -20 0\nv 20 20 0\nv -20 20 0\n\
               v -0.002 -20 0.001\nv 0.002 -20 0.001\nv 0.002 20 0.001\nv -0.002 20 0.001\n\
               usemtl plane\nf 1 2 3\nf 1 3 4\nusemtl strip\nf 5 6 7\nf 5 7 8\n";
    let mtl = "newmtl plane\nKd 0.8 0.8 0.8\nnewmtl strip\nKd 0.05 0.05 0.05\n";
    let plane = lit_mesh(
        "strip",
        obj,
        Some(mtl),
        "position = [0.0, 0.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]",
        "position = [10.0, 6.0, 40.0]\nintensity = [1200.0, 1200.0, 1200.0]",
    );
    let gpu = upload(&plane);
    let (w, h) = (65u32, 49u32);
    let cam = camera("rectilinear:f=1", w, h);
    let one = uniform(&gpu, &cam, 1);
    let strip = |x: u32, y: u32| one.ids[(y * w + x) as usize] >= 2;
    let middle = w / 2;
    for y in 0..h {
        assert!(
            strip(middle, y),
            "the centre of ({middle}, {y}) sees the strip"
        );
        assert!(!strip(middle - 1, y) && !strip(middle + 1, y));
    }
    let (_, rays) = adaptive(&gpu, &cam, 16, 0.02, false);
    for y in 0..h {
        assert_eq!(
            rays[(y * w + middle) as usize],
            1 + 16,
            "pixel ({middle}, {y})"
        );
    }
}

/// Displayed colour is clamped; the box filter is not. A plane lit far past white (radiance
/// above 1 in every channel) ends against a black sky: along its edge a pixel whose colour
/// bends and that has a neighbour brighter than the display shows takes every sample, however
/// well its 2 × 2 estimating samples agree (four that all miss a sliver of the plane would
/// leave it black, where its box average shows white). Judged from the one-ray image, whose
/// pixels near the edge are the ones the adaptive frame traced there.
#[test]
fn a_pixel_beside_an_overexposed_one_takes_every_sample() {
    let plane = lit_plane(
        "overexposed",
        1000.0,
        "position = [0.0, -19.0, 1.5]\nlook_at = [6.0, 0.0, 1.0]",
        "position = [10.0, 6.0, 400.0]\nintensity = [2.0e6, 2.0e6, 2.0e6]",
        false,
    );
    let gpu = upload(&plane);
    let (w, h) = (65u32, 49u32);
    let cam = camera("rectilinear:f=1", w, h);
    let one = uniform(&gpu, &cam, 1);
    let over = |x: u32, y: u32| {
        let c = one.colour[(y * w + x) as usize];
        c[0].max(c[1]).max(c[2]) > 1.0
    };
    let plane_pixels = one.ids.iter().filter(|&&id| id != NO_HIT).count();
    let lit = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| over(x, y))
        .count();
    assert_eq!(lit, plane_pixels, "the whole plane is past white");
    let (_, rays) = adaptive(&gpu, &cam, 16, 0.02, false);
    let mut beside = 0;
    for y in 0..h {
        for x in 0..w {
            let n = rays[(y * w + x) as usize];
            // Pixels the estimating stage took (their centre's ray, then 2 × 2 samples).
            if n < 1 + 4 {
                continue;
            }
            let neighbours = [
                (x.wrapping_sub(1), y),
                (x + 1, y),
                (x, y.wrapping_sub(1)),
                (x, y + 1),
            ];
            if neighbours
                .iter()
                .any(|&(i, j)| i < w && j < h && over(i, j))
            {
                // The centre's ray and 16 samples, the estimate's 4 among them.
                assert_eq!(n, 1 + 16, "pixel ({x}, {y})");
                beside += 1;
            }
        }
    }
    assert!(beside > 40, "{beside} pixels beside the plane's edge");
}

/// Thin wedges against the sky, their tips pointing left at several heights and depths: where
/// a tip reaches into a 4 × 4 block between its corners, all four of which see sky, while a
/// lattice point one spacing beyond a corner along the block's edge sees the wedge (the tip
/// passes between them), the block is not interpolated from its corners (which would paint
/// the tip over with sky) but refined: its centre and the midpoints of its edges are traced.
/// Judged from the one-ray image's hits.
#[test]
fn a_silhouette_beside_a_blocks_corners_refines_it() {
    // Wedge k: tip at x = -4 + 0.37 k, widening to 1.6 high at x = 6, at height 2.3 k - 7.
    let mut obj = String::new();
    for k in 0..7 {
        let (tip, y) = (-4.0 + 0.37 * f64::from(k), 2.3 * f64::from(k) - 7.0);
        obj += &format!("v {tip} 0 {y}\nv 6 0 {}\nv 6 0 {}\n", y - 0.8, y + 0.8);
        let v = 3 * k + 1;
        obj += &format!("f {v} {} {}\n", v + 1, v + 2);
    }
    let wedges = lit_mesh(
        "wedges",
        &obj,
        None,
        "position = [0.0, -10.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]",
        "position = [0.0, -10.0, 0.0]\nintensity = [100.0, 100.0, 100.0]",
    );
    let gpu = upload(&wedges);
    let (w, h) = (65u32, 49u32);
    let cam = camera("rectilinear:f=1", w, h);
    let one = uniform(&gpu, &cam, 1);
    let (_, rays) = adaptive(&gpu, &cam, 1, 0.02, false);
    let (w, h) = (w as usize, h as usize);
    let hit = |&(x, y): &(usize, usize)| one.ids[y * w + x] != NO_HIT;
    let b = ADAPTIVE_BLOCK as usize;
    let mut tips = 0;
    // Whole blocks only (65 × 49 puts the last lattice row and column a block on).
    for y0 in (0..h - 1).step_by(b) {
        for x0 in (0..w - 1).step_by(b) {
            let (x1, y1) = (x0 + b, y0 + b);
            let corners = [(x0, y0), (x1, y0), (x0, y1), (x1, y1)];
            let beside = beside_corners((x0, y0), (x1, y1), (w, h));
            if corners.iter().any(hit) || !beside.iter().any(hit) {
                continue;
            }
            let half = b / 2;
            for (x, y) in [(x0 + half, y0 + half), (x0 + half, y0), (x0, y0 + half)] {
                assert!(
                    rays[y * w + x] > 0,
                    "block at ({x0}, {y0}): ({x}, {y}) untraced"
                );
            }
            let inside = (y0..y1).any(|y| (x0..x1).any(|x| hit(&(x, y))));
            tips += usize::from(inside);
        }
    }
    assert!(
        tips >= 2,
        "{tips} blocks with a tip inside between corners that miss"
    );
}
