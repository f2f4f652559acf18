// The adaptive kernels with hardware ray-query traversal: `adaptive.wgsl` with `bvh_rq.wgsl` in
// place of the software `bvh.wgsl`, as `trace_rq.wgsl` is to `trace.wgsl`.
#swap bvh bvh_rq
#import adaptive
