//! Adaptive sampling's constants (`trace::AdaptivePass`, `wgsl/adaptive.wgsl` and the kernels
//! that import it): its work buffer's layout and what its kernels trace.

/// Storage buffers the adaptive kernels bind beyond the trace kernel's: the work buffer (the
/// per-pixel state and the work list, `trace::AdaptivePass`). With computed directions they
/// bind 8, WebGPU's default limit.
pub const ADAPTIVE_STORAGE_BUFFERS: u32 = 1;

/// Side of the blocks of pixels whose corners adaptive sampling traces first: one ray per
/// `ADAPTIVE_BLOCK`² pixels where the image is smooth.
pub const ADAPTIVE_BLOCK: u32 = 4;
/// Pixels side by side in a row that each invocation of adaptive sampling's per-pixel listing
/// kernels looks at: a workgroup lists `ADAPTIVE_STRIP` times as many pixels for the same
/// barriers and global atomic.
pub const ADAPTIVE_STRIP: u32 = 4;
/// The `u32`s before the list in adaptive sampling's work buffer: the list's length
/// (at `ADAPTIVE_COUNT`), the part of it `trace_list` traces (from `ADAPTIVE_FIRST` to
/// `ADAPTIVE_END`) and how (at `ADAPTIVE_MODE`): a 16-byte header.
pub const ADAPTIVE_HEADER: u32 = 4;
/// Where the work buffer holds the list's length.
pub const ADAPTIVE_COUNT: u32 = 0;
/// The samples per side of adaptive sampling's estimating stage (Dammertz et al.'s error
/// estimate compares the mean of half of them with the mean of all).
pub const ADAPTIVE_ESTIMATE_SIDE: u32 = 2;
/// Where the work buffer holds the first list entry `trace_list` traces.
pub const ADAPTIVE_FIRST: u32 = 1;
/// Where the work buffer holds the end (exclusive) of the entries `trace_list` traces.
pub const ADAPTIVE_END: u32 = 2;
/// Where the work buffer holds what `trace_list` traces: the coarse stage's points, with no
/// list, at `MODE_LATTICE` or `MODE_EVERY_PIXEL` (written before that stage), else the list
/// (0, as the header is cleared before each list is made). So the coarse stage and the stages
/// that trace listed centres share one kernel, which lavapipe compiles once.
pub const ADAPTIVE_MODE: u32 = 3;
/// What an adaptive tracing kernel traces of each pixel (its `LIST_MODE`,
/// `wgsl/adaptive.wgsl`): a shaded ray through the centre (`trace_list`).
pub const MODE_CENTRE: u32 = 0;
/// As [`MODE_CENTRE`]: every sample (`trace_samples`).
pub const MODE_SAMPLES: u32 = 1;
/// As [`MODE_CENTRE`]: the centre ray's first hit alone, for the ground truth (`trace_list`).
pub const MODE_TRUTH: u32 = 2;
/// As [`MODE_CENTRE`]: the 2 × 2 estimating samples and their error estimate
/// (`trace_samples`).
pub const MODE_ESTIMATE: u32 = 3;
/// At [`ADAPTIVE_MODE`]: `trace_list` traces the lattice's points, the coarse stage, with no
/// list.
pub const MODE_LATTICE: u32 = 4;
/// At [`ADAPTIVE_MODE`]: `trace_list` traces every pixel, the coarse stage of
/// `trace::Adaptive::every_pixel`, with no list.
pub const MODE_EVERY_PIXEL: u32 = 5;
/// What a pixel's state in the work buffer keeps, in place of what its centre saw, when it
/// demands every sample: its 2 × 2 estimating samples disagreed, or a neighbour is brighter
/// than the display shows (`wgsl/adaptive.wgsl`'s other keys sit above it).
pub const ADAPTIVE_KEY_MORE: u32 = 0xffff_fffc;
