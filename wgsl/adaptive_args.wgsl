// Turns adaptive sampling's work list into the indirect dispatch of `adaptive.wgsl`'s
// `trace_list` or `trace_samples`, PER_GROUP list entries a workgroup: one invocation. It sets
// the part of the list traced (entries ADAPTIVE_FIRST to ADAPTIVE_END of the header): the
// whole list, or with SLICE > 0 the next SLICE entries after the last part's end, so that
// progressive refinement traces a long list over several frames. The arguments live in a
// buffer of their own, since a dispatch may not read its indirect arguments from a buffer it
// writes.

// The work buffer of `adaptive.wgsl`: its header, here.
@group(0) @binding(0) var<storage, read_write> work: array<u32>;
// Workgroups across, down and deep.
@group(0) @binding(1) var<storage, read_write> dispatch: array<u32, 3>;

// List entries per dispatch; 0: all of them.
override SLICE: u32 = 0u;
// List entries per workgroup of the kernel dispatched.
override PER_GROUP: u32 = WORKGROUP_1D;

@compute @workgroup_size(1)
fn main() {
    let count = work[ADAPTIVE_COUNT];
    var first = 0u;
    var end = count;
    if SLICE > 0u {
        first = min(work[ADAPTIVE_END], count);
        end = first + min(SLICE, count - first);
    }
    work[ADAPTIVE_FIRST] = first;
    work[ADAPTIVE_END] = end;
    let groups = (end - first + PER_GROUP - 1u) / PER_GROUP;
    // Rows of at most 65535 workgroups (the least limit on a dimension).
    let rows = max((groups + 65534u) / 65535u, 1u);
    dispatch[0] = (groups + rows - 1u) / rows;
    dispatch[1] = rows;
    dispatch[2] = 1u;
}
