//! Covered cells on the device: the GPU side of [`crate::lbm::CoveredCells`].
//!
//! A coupling method hands the lattice its collision term as WGSL ([`CoveredTerm`]): a
//! function `covered_term(e, g, &post) -> vec2<real>` that, like
//! [`crate::lbm::CoveredCells::apply`], turns the fluid collision `post` of the pre-collision
//! populations `g` of cover entry `e` into the final post-collision populations and returns the
//! momentum its term gave the fluid. It reads its per-entry values from `covered_values`
//! (`values` of them per entry), and the lattice's collision coefficients from `coef`.
//!
//! Per cover ([`GpuLattice::set_cover`]): the previous cover's cells are cleared from the
//! per-cell index and the new ones marked (`cover.wgsl`, one dispatch each), the entries'
//! values uploaded and their momenta zeroed on the device; the step kernel then sums each
//! entry's momentum over the steps until the next cover (one thread per cell writes its own
//! entry: no races), and only those sums come back ([`GpuLattice::covered_exchange`]).

use wgpu::util::DeviceExt;

use super::{
    bind_group, bind_group_layout, zeroed, GpuLattice, Real, COVERED_EXCHANGE, COVERED_INDEX,
    COVERED_VALUES, GROUP_X,
};

/// A coupling method's term on covered cells, in WGSL (see the module documentation).
#[derive(Clone, Copy, Debug)]
pub struct CoveredTerm {
    /// The source of `fn covered_term(e: u32, g: array<real, 9>, post: ptr<function,
    /// array<real, 9>>) -> vec2<real>`.
    pub source: &'static str,
    /// Values per cover entry in `covered_values`.
    pub values: usize,
}

/// The term of a lattice built without one (never called: the kernel's `COVERED` is false).
pub(super) const NO_TERM: &str = "fn covered_term(e: u32, g: array<real, 9>, \
     post: ptr<function, array<real, 9>>) -> vec2<real> { return vec2<real>(0.0); }";

/// Most workgroups one marking dispatch launches (the kernel strides over the rest).
const MARK_GROUPS: u32 = 4096;

/// The device's cover: the marking kernels, the cells of the current cover and the sizes.
pub(super) struct DeviceCover {
    /// Marking kernels that clear and that set.
    mark: [wgpu::ComputePipeline; 2],
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    /// The current cover's entry count followed by its cells.
    cells: wgpu::Buffer,
    /// Entries of the current cover, and how many the buffers hold.
    entries: usize,
    capacity: usize,
    /// Values per entry.
    values: usize,
}

impl DeviceCover {
    /// The marking kernels for the per-cell `index`, with room for no entry yet.
    pub(super) fn new(device: &wgpu::Device, term: &CoveredTerm, index: &wgpu::Buffer) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("cover.wgsl"),
            source: wgpu::ShaderSource::Wgsl(include_str!("cover.wgsl").into()),
        });
        let layout = bind_group_layout(device, "cover", 2, &[0]);
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cover"),
            bind_group_layouts: &[&layout],
            push_constant_ranges: &[],
        });
        let mark = [0.0, 1.0].map(|set| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("mark"),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some("mark"),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &[("SET", set)],
                    zero_initialize_workgroup_memory: false,
                },
                cache: None,
            })
        });
        let cells = cells_buffer(device, &[0]);
        let group = bind_group(device, "cover", &layout, &[index, &cells]);
        DeviceCover {
            mark,
            layout,
            group,
            cells,
            entries: 0,
            capacity: 0,
            values: term.values,
        }
    }
}

/// A buffer of the entry count followed by `cells`.
fn cells_buffer(device: &wgpu::Device, contents: &[u32]) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("covered cells"),
        contents: bytemuck::cast_slice(contents),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
    })
}

impl GpuLattice {
    fn cover_mut(&mut self) -> &mut DeviceCover {
        self.cover
            .as_mut()
            .expect("the lattice was built with a covered term")
    }

    /// One marking dispatch over the current cover's entries; when setting, their momentum
    /// sums are zeroed on the device first (`bytes` of them).
    fn mark(&self, set: bool, bytes: u64) {
        let cover = self.cover.as_ref().expect("built with a covered term");
        if cover.entries == 0 {
            return;
        }
        let mut encoder = self.device.create_command_encoder(&Default::default());
        if set {
            encoder.clear_buffer(&self.buffers[COVERED_EXCHANGE], 0, Some(bytes));
        }
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&cover.mark[usize::from(set)]);
            pass.set_bind_group(0, &cover.group, &[]);
            let groups = (cover.entries as u32).div_ceil(GROUP_X).min(MARK_GROUPS);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        self.queue.submit([encoder.finish()]);
    }

    /// Replace the cover: the cells (ascending, unique) with `values` (the term's values per
    /// entry, entry after entry); the momenta the entries exchanged start from zero. Only the
    /// cells and values go up.
    pub fn set_cover<T: Real>(&mut self, cells: &[u32], values: &[T]) {
        let n = cells.len();
        let per = self.cover_mut().values;
        assert_eq!(values.len(), per * n, "{per} values per covered cell");
        // Clear the previous cover's cells, from the buffer that still holds them.
        self.mark(false, 0);
        if n > self.cover_mut().capacity {
            let capacity = n.max(2 * self.cover_mut().capacity);
            let usage = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
            let size = std::mem::size_of::<T>();
            self.buffers[COVERED_VALUES] =
                zeroed(&self.device, "covered values", per * capacity * size, usage);
            self.buffers[COVERED_EXCHANGE] =
                zeroed(&self.device, "covered exchange", 2 * capacity * size, usage);
            let group = bind_group(
                &self.device,
                "lattice",
                &self.group_layout,
                &self.buffers.iter().collect::<Vec<_>>(),
            );
            self.bind_group = group;
            let cells = cells_buffer(&self.device, &vec![0; 1 + capacity]);
            let cover = self.cover.as_mut().expect("built with a covered term");
            cover.group = bind_group(
                &self.device,
                "cover",
                &cover.layout,
                &[&self.buffers[COVERED_INDEX], &cells],
            );
            (cover.cells, cover.capacity) = (cells, capacity);
        }
        let cover = self.cover.as_ref().expect("built with a covered term");
        self.queue
            .write_buffer(&cover.cells, 0, bytemuck::bytes_of(&(n as u32)));
        if n > 0 {
            self.queue
                .write_buffer(&cover.cells, 4, bytemuck::cast_slice(cells));
            self.queue.write_buffer(
                &self.buffers[COVERED_VALUES],
                0,
                bytemuck::cast_slice(values),
            );
        }
        self.cover_mut().entries = n;
        self.mark(true, (2 * n * std::mem::size_of::<T>()) as u64);
    }

    /// The momentum each entry of the cover exchanged with the fluid, summed over the steps
    /// since [`GpuLattice::set_cover`] (lattice units, entry order): 2 values per entry come
    /// back.
    pub fn covered_exchange<T: Real>(&self) -> Vec<[f64; 2]> {
        let n = self.cover.as_ref().map_or(0, |c| c.entries);
        if n == 0 {
            return Vec::new();
        }
        let m: Vec<T> = self.read(&self.buffers[COVERED_EXCHANGE]);
        m[..2 * n]
            .chunks_exact(2)
            .map(|p| [p[0].f64(), p[1].f64()])
            .collect()
    }

    /// Overwrite the sums [`GpuLattice::covered_exchange`] returns (to continue a run): those
    /// of the first entries, in entry order (the others stay as [`GpuLattice::set_cover`] left
    /// them, zero).
    pub fn set_covered_exchange<T: Real>(&mut self, sums: &[[f64; 2]]) {
        let n = self.cover.as_ref().map_or(0, |c| c.entries).min(sums.len());
        let values: Vec<T> = sums[..n].iter().flatten().map(|&v| T::c(v)).collect();
        if n > 0 {
            self.queue.write_buffer(
                &self.buffers[COVERED_EXCHANGE],
                0,
                bytemuck::cast_slice(&values),
            );
        }
    }
}
