// Turns the length of adaptive sampling's work list into the indirect dispatch of
// `adaptive.wgsl`'s `trace_list`: one invocation. The arguments live in a buffer of their own,
// since a dispatch may not read its indirect arguments from a buffer it writes.

// The work buffer of `adaptive.wgsl`, read only here.
@group(0) @binding(0) var<storage, read> work: array<u32>;
// Workgroups across, down and deep.
@group(0) @binding(1) var<storage, read_write> dispatch: array<u32, 3>;

@compute @workgroup_size(1)
fn main() {
    let groups = (work[ADAPTIVE_COUNT] + WORKGROUP_1D - 1u) / WORKGROUP_1D;
    // Rows of at most 65535 workgroups (the least limit on a dimension).
    let rows = max((groups + 65534u) / 65535u, 1u);
    dispatch[0] = (groups + rows - 1u) / rows;
    dispatch[1] = rows;
    dispatch[2] = 1u;
}
