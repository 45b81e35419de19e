// Marks the cells of a cover in the per-cell index of the step kernel (`covered_index`):
// entry e of the cover, cells[1 + e], gets e when SET, and NONE (not covered) otherwise, which
// clears the previous cover before the next is marked. cells[0] is the number of entries.

override SET: bool;
const NONE: u32 = 0xffffffffu;

@group(0) @binding(0) var<storage, read_write> index: array<u32>;
@group(0) @binding(1) var<storage, read> cells: array<u32>;

// Grid-stride: any number of workgroups covers every entry.
@compute @workgroup_size(64, 1, 1)
fn mark(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) n: vec3<u32>) {
    for (var e = id.x; e < cells[0]; e += 64u * n.x) {
        index[cells[1u + e]] = select(NONE, e, SET);
    }
}
