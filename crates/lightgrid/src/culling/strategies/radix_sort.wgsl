// LSD radix sort of (key, value) pairs, 4 bits per pass, stable (radix_sort.rs drives it).
// Per pass: local_main sorts each block of ASSIGN_THREADS pairs by the digit in workgroup
// memory (four stable one-bit splits), writes the sorted block to tmp and the block's digit
// counts to `hist` (digit-major: hist[digit * blocks + block]); a prefix sum of `hist` gives
// every (digit, block) its output offset; scatter_main moves each pair there from tmp.
// Positions past `n` in the last block carry key 0xffffffff, sort last and are never written.

@group(0) @binding(0) var<uniform> sp: SortParams;
@group(0) @binding(1) var<storage, read_write> keys: array<u32>;
@group(0) @binding(2) var<storage, read_write> vals: array<u32>;
@group(0) @binding(3) var<storage, read_write> tmp_keys: array<u32>;
@group(0) @binding(4) var<storage, read_write> tmp_vals: array<u32>;
@group(0) @binding(5) var<storage, read_write> hist: array<u32>;
@group(0) @binding(6) var<storage, read_write> hist_offsets: array<u32>;

const RADIX_DIGITS: u32 = 16u;

var<workgroup> s_key: array<u32, ASSIGN_THREADS>;
var<workgroup> s_val: array<u32, ASSIGN_THREADS>;
var<workgroup> s_scan: array<u32, ASSIGN_THREADS>;
var<workgroup> digit_count: array<atomic<u32>, RADIX_DIGITS>;
var<workgroup> digit_start: array<u32, RADIX_DIGITS>;

fn block_of(wg: vec3<u32>, nwg: vec3<u32>) -> u32 {
    return wg.y * nwg.x + wg.x;
}

// Pairs of `block` that exist.
fn block_len(block: u32) -> u32 {
    return min(ASSIGN_THREADS, sp.n - block * ASSIGN_THREADS);
}

@compute @workgroup_size(ASSIGN_THREADS)
fn local_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let block = block_of(wg, nwg);
    if (block >= sp.blocks) {
        return;
    }
    let base = block * ASSIGN_THREADS;
    let len = block_len(block);
    var key = 0xffffffffu;
    var val = 0u;
    if (li < len) {
        key = keys[base + li];
        val = vals[base + li];
    }
    if (li < RADIX_DIGITS) {
        atomicStore(&digit_count[li], 0u);
    }
    for (var b = 0u; b < 4u; b = b + 1u) {
        let bit = (key >> (sp.shift + b)) & 1u;
        s_scan[li] = 1u - bit;
        workgroupBarrier();
        for (var d = 1u; d < ASSIGN_THREADS; d = d * 2u) {
            var v = 0u;
            if (li >= d) {
                v = s_scan[li - d];
            }
            workgroupBarrier();
            s_scan[li] += v;
            workgroupBarrier();
        }
        let zeros = s_scan[ASSIGN_THREADS - 1u];
        let zeros_before = s_scan[li] - (1u - bit);
        var dst = zeros_before;
        if (bit == 1u) {
            dst = zeros + li - zeros_before;
        }
        workgroupBarrier();
        s_key[dst] = key;
        s_val[dst] = val;
        workgroupBarrier();
        key = s_key[li];
        val = s_val[li];
        workgroupBarrier();
    }
    if (li < len) {
        tmp_keys[base + li] = key;
        tmp_vals[base + li] = val;
        atomicAdd(&digit_count[(key >> sp.shift) & 15u], 1u);
    }
    workgroupBarrier();
    if (li < RADIX_DIGITS) {
        hist[li * sp.blocks + block] = atomicLoad(&digit_count[li]);
    }
}

@compute @workgroup_size(ASSIGN_THREADS)
fn scatter_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let block = block_of(wg, nwg);
    if (block >= sp.blocks) {
        return;
    }
    let base = block * ASSIGN_THREADS;
    let len = block_len(block);
    var digit = RADIX_DIGITS;
    if (li < len) {
        digit = (tmp_keys[base + li] >> sp.shift) & 15u;
    }
    s_scan[li] = digit;
    workgroupBarrier();
    if (li < len && (li == 0u || s_scan[li - 1u] != digit)) {
        digit_start[digit] = li;
    }
    workgroupBarrier();
    if (li < len) {
        let dst = hist_offsets[digit * sp.blocks + block] + li - digit_start[digit];
        keys[dst] = tmp_keys[base + li];
        vals[dst] = tmp_vals[base + li];
    }
}
