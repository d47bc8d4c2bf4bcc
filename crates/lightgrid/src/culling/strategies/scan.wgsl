// Exclusive prefix sum of `scan_src` (its bound length) into `scan_dst`, and the total into
// `scan_total`, by one workgroup: each invocation sums a contiguous chunk, a Hillis-Steele scan
// combines the chunk sums, and each invocation writes its chunk's running offsets.
// The chunk loops are bounded by the buffers, not by frame data: at most 2^20 lights or
// 2^25 / 16 sort histogram entries (a 128 MiB pair buffer), so 2 x 8192 iterations per
// invocation, well below llvmpipe's loop guard (65,536); this pass binds no frame counters.

@group(0) @binding(0) var<storage, read> scan_src: array<u32>;
@group(0) @binding(1) var<storage, read_write> scan_dst: array<u32>;
@group(0) @binding(2) var<storage, read_write> scan_total: array<u32>;

var<workgroup> chunk_sums: array<u32, ASSIGN_THREADS>;

@compute @workgroup_size(ASSIGN_THREADS)
fn main(@builtin(local_invocation_index) li: u32) {
    let n = arrayLength(&scan_src);
    let chunk = (n + ASSIGN_THREADS - 1u) / ASSIGN_THREADS;
    let first = li * chunk;
    let last = min(first + chunk, n);
    var sum = 0u;
    for (var i = first; i < last; i = i + 1u) {
        sum += scan_src[i];
    }
    chunk_sums[li] = sum;
    workgroupBarrier();
    for (var d = 1u; d < ASSIGN_THREADS; d = d * 2u) {
        var v = 0u;
        if (li >= d) {
            v = chunk_sums[li - d];
        }
        workgroupBarrier();
        chunk_sums[li] += v;
        workgroupBarrier();
    }
    var offset = chunk_sums[li] - sum;
    for (var i = first; i < last; i = i + 1u) {
        let v = scan_src[i];
        scan_dst[i] = offset;
        offset += v;
    }
    if (li == ASSIGN_THREADS - 1u) {
        scan_total[0] = chunk_sums[li];
    }
}
