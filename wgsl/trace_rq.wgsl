// The trace kernel with hardware ray-query traversal: `trace.wgsl` with `bvh_rq.wgsl` in place
// of the software `bvh.wgsl`, so that every line of lens and shading code is shared.
#swap bvh bvh_rq
#import trace
