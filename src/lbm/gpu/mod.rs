//! The lattice Boltzmann step on a GPU through wgpu (feature `gpu`).
//!
//! The device holds the populations in the CPU's layout (structure of arrays, padded stride,
//! [`super::lattice`]) and runs the same in-place AA stream–collide (`stream_collide.wgsl`),
//! one thread per cell, one dispatch per step. AA rather than two copies (A→B): it halves the
//! device memory, moves the same 2·9 values per cell and step, and leaves the populations in
//! exactly the CPU's state (values and parity), so a download is a CPU lattice again: frames
//! and checkpoints use the CPU code unchanged, and a checkpoint taken on one back end resumes
//! on the other.
//!
//! Nodes whose 8 neighbours are fluid ("bulk") find their neighbours by index arithmetic;
//! the others ("special": next to a wall or a solid) read a table of 9 link codes built from
//! the CPU lattice's own plan, so both back ends apply the same bounce-back on the same
//! links. The populations stay on the device between steps; [`GpuFluid`] downloads them only
//! for what needs the whole lattice (a frame, a single cell, a checkpoint): time-series sums,
//! probes and stability checks are reduced on the device (`observe` and `probe` in the kernel
//! source), and obstacle loads read back the per-link momenta only.
//!
//! Built: BGK and MRT, Smagorinsky LES, Guo forcing, periodic edges, half-way bounce-back
//! walls at rest or moving, Zou–He velocity and pressure edges (the closure of
//! [`super::boundary`] on the nodes the CPU plan marks, in the kernel's precision), obstacles
//! (half-way or Yu's interpolated bounce-back: a second kernel over the links after each step,
//! which also stores the momentum each link exchanged; the loads are summed on the host in link
//! order when observed, as the CPU sums them), a coupling method's term on the cells its solids
//! cover (`covered.rs`: the partially saturated cells), in f32, and in f64 where the adapter
//! offers `SHADER_F64`.

use std::cell::{Cell, Ref, RefCell};

use wgpu::util::DeviceExt;

use super::boundary::{Neighbour, ZouHe};
use super::collision::{Collider, CollisionModel};
use super::d2q9::Q;
use super::lattice::Lattice;
use super::observation::Observation;
use super::obstacle::Obstacles;
use super::real::Real;
use super::solver::{Fluid, Lbm, LbmState, Macroscopic};
use crate::units::Units;
use crate::Result;

mod covered;

pub use covered::CoveredTerm;

/// The kernel's source, with `alias real = f32;` rewritten for f64.
const SOURCE: &str = include_str!("stream_collide.wgsl");
/// Threads per workgroup along x (the kernel's `@workgroup_size`).
const GROUP_X: u32 = 64;
/// Steps encoded into one command buffer.
const STEPS_PER_SUBMIT: u64 = 256;
/// `kind` of a bulk cell and of a solid cell (`stream_collide.wgsl`).
const BULK: u32 = u32::MAX;
const SOLID: u32 = u32::MAX - 1;
/// Link-code bit of a bounce-back link, and the code of an open (Zou–He) link.
const BOUNCE: u32 = 1 << 31;
const OPEN: u32 = u32::MAX;
/// Storage buffers the step kernels bind (group 0), and the observation kernels besides them
/// (group 1).
const BINDINGS: u32 = 12;
/// Group-0 bindings of the populations, the obstacle links' momenta and the covered cells'
/// index, values and momenta.
const F: usize = 0;
const EXCHANGED: usize = 7;
const COVERED_INDEX: usize = 9;
const COVERED_VALUES: usize = 10;
const COVERED_EXCHANGE: usize = 11;
const OBSERVE_BINDINGS: u32 = 2;

/// A GPU: the adapter wgpu picked, its device and queue.
pub struct Gpu {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// The adapter's name and driver, for reports.
    pub name: String,
    /// Does the adapter offer `SHADER_F64`?
    pub f64: bool,
}

impl Gpu {
    /// The highest-performance adapter among Vulkan, Metal and DX12 ones, with its largest
    /// limits. Fails with what was looked for when there is none.
    pub fn new() -> std::result::Result<Gpu, String> {
        let instance = wgpu::Instance::new(&wgpu::InstanceDescriptor {
            backends: wgpu::Backends::PRIMARY,
            ..Default::default()
        });
        let options = wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: None,
        };
        let adapter = pollster::block_on(instance.request_adapter(&options)).map_err(|e| {
            format!(
                "no GPU adapter found ({e}): looked for Vulkan, Metal and DX12 adapters through \
                 wgpu; install the GPU's Vulkan driver (without a GPU, a software one such as \
                 Debian's mesa-vulkan-drivers), or run with backend = \"cpu\""
            )
        })?;
        let info = adapter.get_info();
        let f64 = adapter.features().contains(wgpu::Features::SHADER_F64);
        let features = if f64 {
            wgpu::Features::SHADER_F64
        } else {
            wgpu::Features::empty()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("granflow"),
            required_features: features,
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| format!("the GPU adapter {} refused a device: {e}", info.name))?;
        Ok(Gpu {
            device,
            queue,
            name: format!("{} ({:?}, {})", info.name, info.backend, info.driver_info),
            f64,
        })
    }

    /// Copy bandwidth of the device (GB/s, read + write) between two buffers of `bytes`
    /// each (at most its largest buffer); best of 5.
    pub fn copy_bandwidth(&self, bytes: usize) -> f64 {
        let limit = self.device.limits().max_buffer_size;
        let size = (bytes as u64).clamp(1 << 20, limit) / 4 * 4;
        let buffer = |usage| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("copy bandwidth"),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let src = buffer(wgpu::BufferUsages::COPY_SRC);
        let dst = buffer(wgpu::BufferUsages::COPY_DST);
        let copy = || {
            let mut encoder = self.device.create_command_encoder(&Default::default());
            encoder.copy_buffer_to_buffer(&src, 0, &dst, 0, size);
            self.queue.submit([encoder.finish()]);
            self.device
                .poll(wgpu::PollType::wait_indefinitely())
                .expect("the GPU device was lost");
        };
        copy();
        (0..5)
            .map(|_| {
                let t0 = std::time::Instant::now();
                copy();
                2.0 * size as f64 / t0.elapsed().as_secs_f64() / 1e9
            })
            .fold(0.0, f64::max)
    }
}

/// A storage buffer of `bytes` bytes (at least 4: a binding may not be empty), initialised to
/// zero.
fn zeroed(
    device: &wgpu::Device,
    label: &str,
    bytes: usize,
    usage: wgpu::BufferUsages,
) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(4).next_multiple_of(4) as u64,
        usage: wgpu::BufferUsages::STORAGE | usage,
        mapped_at_creation: false,
    })
}

/// A bind group of `buffers` at bindings 0, 1, … of `layout`.
fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .enumerate()
        .map(|(i, b)| wgpu::BindGroupEntry {
            binding: i as u32,
            resource: b.as_entire_binding(),
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &entries,
    })
}

/// A bind-group layout of `n` storage buffers for the compute stage, `written` ones
/// read–write, the others read-only.
fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    n: u32,
    written: &[u32],
) -> wgpu::BindGroupLayout {
    let entries: Vec<wgpu::BindGroupLayoutEntry> = (0..n)
        .map(|binding| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage {
                    read_only: !written.contains(&binding),
                },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        })
        .collect();
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &entries,
    })
}

/// The buffers of an observation: its probe cells, and where the row sums and probes land.
struct Observer {
    probes: Vec<u32>,
    results: wgpu::Buffer,
    group: wgpu::BindGroup,
}

/// A lattice's populations on the device, its obstacle links, and the pipelines that advance
/// them: the step and the obstacles' after-step, each for an even and an odd step.
pub struct GpuLattice {
    device: wgpu::Device,
    queue: wgpu::Queue,
    /// Pipelines of the odd and the even step.
    pipelines: [wgpu::ComputePipeline; 2],
    /// Obstacle after-step pipelines after an odd and after an even step.
    after: [wgpu::ComputePipeline; 2],
    /// Row sums and probe pipelines before an odd and before an even step.
    observers: [[wgpu::ComputePipeline; 2]; 2],
    observe_layout: wgpu::BindGroupLayout,
    /// The probe cells of the last observation, with its result buffer and bind group.
    observation: RefCell<Option<Observer>>,
    /// Number of obstacle links.
    links: u32,
    /// The buffers of group 0 (populations at [`F`], the obstacle links' momenta at
    /// [`EXCHANGED`], the covered cells at [`COVERED_INDEX`] …), its layout and bind group.
    buffers: Vec<wgpu::Buffer>,
    group_layout: wgpu::BindGroupLayout,
    bind_group: wgpu::BindGroup,
    /// The covered cells of a coupling's term, when built with one.
    cover: Option<covered::DeviceCover>,
    /// Workgroups of a step: along x, and one row each along y.
    groups: [u32; 2],
    /// True when the next step is even.
    even: bool,
}

impl GpuLattice {
    /// Upload `lattice` (populations, parity, walls) with the links of its `obstacles` and
    /// build the kernels for `collider`, with the covered cells' `term` of a coupling when
    /// given ([`CoveredTerm`]). Fails with the reason for what the adapter lacks
    /// (`SHADER_F64` for f64, buffers as large as the lattice, fourteen storage buffers per
    /// kernel).
    pub fn new<T: Real>(
        gpu: &Gpu,
        lattice: &Lattice<T>,
        collider: &Collider<T>,
        obstacles: &Obstacles,
        term: Option<&CoveredTerm>,
    ) -> std::result::Result<Self, String> {
        if T::NAME == "f64" && !gpu.f64 {
            return Err(format!(
                "the GPU adapter {} lacks the SHADER_F64 feature that f64 populations need: \
                 use precision = \"f32\" or backend = \"cpu\"",
                gpu.name
            ));
        }
        let (nx, ny) = (lattice.nx, lattice.ny);
        let (pops, even) = lattice.state();
        let stride = pops.len() / Q;
        let limits = gpu.device.limits();
        let bytes = std::mem::size_of_val(pops.as_slice()) as u64;
        if bytes > u64::from(limits.max_storage_buffer_binding_size) || stride >= BOUNCE as usize {
            return Err(format!(
                "the lattice's populations ({} MiB) exceed the GPU adapter's largest storage \
                 buffer ({} MiB): use a smaller lattice or backend = \"cpu\"",
                bytes >> 20,
                limits.max_storage_buffer_binding_size >> 20
            ));
        }
        let needed = BINDINGS + OBSERVE_BINDINGS;
        if limits.max_storage_buffers_per_shader_stage < needed {
            return Err(format!(
                "the GPU adapter {} binds {} storage buffers per kernel, fewer than the {needed} \
                 the lattice kernels need: use backend = \"cpu\"",
                gpu.name, limits.max_storage_buffers_per_shader_stage
            ));
        }
        if ny as u32 > limits.max_compute_workgroups_per_dimension {
            return Err(format!(
                "the lattice has {ny} rows, more than the GPU adapter dispatches ({})",
                limits.max_compute_workgroups_per_dimension
            ));
        }
        let kind: Vec<u32> = (0..nx * ny)
            .map(|c| match lattice.special_of[c] {
                _ if lattice.is_solid(c) => SOLID,
                u32::MAX => BULK,
                s => s,
            })
            .collect();
        let mut special_links: Vec<u32> = lattice
            .specials
            .iter()
            .flat_map(|s| {
                s.nb.map(|nb| match nb {
                    Neighbour::Fluid(k) => k,
                    Neighbour::Bounce(w) => BOUNCE | u32::from(w),
                    Neighbour::Open => OPEN,
                })
            })
            .collect();
        let mut zou_he: Vec<T> = lattice
            .specials
            .iter()
            .flat_map(|s| {
                let Some(node) = s.zou_he else {
                    return [0.0; 5];
                };
                let [nx, ny] = node.normal.map(f64::from);
                match node.value {
                    ZouHe::Velocity([ux, uy]) => [1.0, nx, ny, ux, uy],
                    ZouHe::Pressure(rho) => [2.0, nx, ny, rho, 0.0],
                }
            })
            .map(T::c)
            .collect();
        // A binding may not be empty.
        special_links.resize(special_links.len().max(Q), 0);
        zou_he.resize(zou_he.len().max(5), T::zero());
        let corr: Vec<T> = lattice.wall_corr.iter().flatten().copied().collect();
        let mut solid_links: Vec<u32> = obstacles
            .links()
            .iter()
            .flat_map(|l| {
                let behind = obstacles.interpolated_behind(l).unwrap_or(u32::MAX);
                [l.cell, u32::from(l.dir), behind]
            })
            .collect();
        let mut link_q: Vec<T> = obstacles.links().iter().map(|l| T::c(l.q)).collect();
        let links = link_q.len() as u32;
        solid_links.resize(solid_links.len().max(3), 0);
        link_q.resize(link_q.len().max(1), T::zero());
        let s = match collider.model {
            CollisionModel::Bgk => [0.0; 3],
            CollisionModel::Mrt(r) => [r.s_e, r.s_eps, r.s_q],
        };
        let coef: Vec<T> = [
            1.0 / collider.tau,
            collider.tau,
            18.0 * collider.smagorinsky.unwrap_or(0.0).powi(2),
            collider.force[0],
            collider.force[1],
            s[0],
            s[1],
            s[2],
        ]
        .map(T::c)
        .to_vec();

        let device = gpu.device.clone();
        let storage = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | usage,
            })
        };
        let copy = wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let read = wgpu::BufferUsages::empty();
        let (cells, real) = (nx * ny, std::mem::size_of::<T>());
        let buffers = vec![
            storage("populations", bytemuck::cast_slice(&pops), copy),
            storage("kind", bytemuck::cast_slice(&kind), read),
            storage("links", bytemuck::cast_slice(&special_links), read),
            storage("wall terms", bytemuck::cast_slice(&corr), read),
            storage("collision", bytemuck::cast_slice(&coef), read),
            storage("obstacle links", bytemuck::cast_slice(&solid_links), read),
            storage("link q", bytemuck::cast_slice(&link_q), read),
            storage("exchanged", bytemuck::cast_slice(&link_q), copy),
            storage("Zou-He nodes", bytemuck::cast_slice(&zou_he), read),
            // The covered cells: an index per cell (only with a term; none covered), entries'
            // values and momenta (grown by `set_cover`).
            storage(
                "covered index",
                bytemuck::cast_slice(&vec![u32::MAX; if term.is_some() { cells } else { 1 }]),
                read,
            ),
            zeroed(&device, "covered values", real, copy),
            zeroed(&device, "covered exchange", real, copy),
        ];
        let term_source = term.map_or(covered::NO_TERM, |t| t.source);
        let source = format!("{SOURCE}\n{term_source}").replacen(
            "alias real = f32;",
            &format!("alias real = {};", T::NAME),
            1,
        );
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("stream_collide.wgsl"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        // Bindings 0 (the populations) and 7 and 11 (momenta exchanged) are written.
        let group_layout = bind_group_layout(
            &device,
            "lattice",
            BINDINGS,
            &[F as u32, EXCHANGED as u32, COVERED_EXCHANGE as u32],
        );
        // Group 1 of the observation kernels: binding 0 (the results) is written.
        let observe_layout = bind_group_layout(&device, "observation", OBSERVE_BINDINGS, &[0]);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("lattice"),
            bind_group_layouts: &[&group_layout],
            push_constant_ranges: &[],
        });
        let observe_pipeline_layout =
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some("observation"),
                bind_group_layouts: &[&group_layout, &observe_layout],
                push_constant_ranges: &[],
            });
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        let pipeline = |entry: &str, even: bool, layout: &wgpu::PipelineLayout| {
            let constants = [
                ("NX", nx as f64),
                ("NY", ny as f64),
                ("STRIDE", stride as f64),
                ("EVEN", flag(even)),
                (
                    "MRT",
                    flag(matches!(collider.model, CollisionModel::Mrt(_))),
                ),
                ("LES", flag(collider.smagorinsky.is_some())),
                ("FORCE", flag(collider.force != [0.0, 0.0])),
                ("LINKS", f64::from(links)),
                ("COVERED", flag(term.is_some())),
            ];
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants: &constants,
                    zero_initialize_workgroup_memory: false,
                },
                cache: None,
            })
        };
        let pipelines = [false, true].map(|even| pipeline("stream_collide", even, &layout));
        let after = [false, true].map(|even| pipeline("after_step", even, &layout));
        let observers = [false, true].map(|even| {
            [
                pipeline("observe", even, &observe_pipeline_layout),
                pipeline("probe", even, &observe_pipeline_layout),
            ]
        });
        let bind_group = bind_group(
            &device,
            "lattice",
            &group_layout,
            &buffers.iter().collect::<Vec<_>>(),
        );
        let cover = term.map(|t| covered::DeviceCover::new(&device, t, &buffers[COVERED_INDEX]));
        Ok(GpuLattice {
            device,
            queue: gpu.queue.clone(),
            pipelines,
            after,
            observers,
            observe_layout,
            observation: RefCell::new(None),
            links,
            buffers,
            group_layout,
            bind_group,
            cover,
            groups: [(nx as u32).div_ceil(GROUP_X), ny as u32],
            even,
        })
    }

    /// Advance `steps` steps on the device (nothing is read back).
    pub fn run(&mut self, steps: u64) {
        let mut left = steps;
        while left > 0 {
            let batch = left.min(STEPS_PER_SUBMIT);
            let mut encoder = self.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_bind_group(0, &self.bind_group, &[]);
                for _ in 0..batch {
                    let parity = usize::from(self.even);
                    pass.set_pipeline(&self.pipelines[parity]);
                    pass.dispatch_workgroups(self.groups[0], self.groups[1], 1);
                    if self.links > 0 {
                        pass.set_pipeline(&self.after[parity]);
                        pass.dispatch_workgroups(self.links.div_ceil(GROUP_X), 1, 1);
                    }
                    self.even = !self.even;
                }
            }
            self.queue.submit([encoder.finish()]);
            left -= batch;
        }
    }

    /// Wait until every step submitted so far has run.
    pub fn finish(&self) {
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .expect("the GPU device was lost");
    }

    /// The contents of `buffer`, read back.
    fn read<T: Real>(&self, buffer: &wgpu::Buffer) -> Vec<T> {
        let size = buffer.size();
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read back"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| {
            r.expect("mapping a GPU buffer for reading failed")
        });
        self.finish();
        let values: Vec<T> = bytemuck::cast_slice(&slice.get_mapped_range()).to_vec();
        staging.unmap();
        values
    }

    /// Sums over the fluid cells and the state of the `probes` cells as the next step will see
    /// them, reduced on the device (`observe` and `probe` in the kernel source): 4 values per
    /// row and 3 per probe come back, summed over the rows on the host in row order.
    pub fn observe<T: Real>(&self, probes: &[usize]) -> Observation {
        let cells: Vec<u32> = probes.iter().map(|&c| c as u32).collect();
        let mut slot = self.observation.borrow_mut();
        if slot.as_ref().is_none_or(|o| o.probes != cells) {
            *slot = Some(self.observer::<T>(cells));
        }
        let o = slot.as_ref().expect("set above");
        let [rows, probe] = &self.observers[usize::from(self.even)];
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &self.bind_group, &[]);
            pass.set_bind_group(1, &o.group, &[]);
            pass.set_pipeline(rows);
            pass.dispatch_workgroups(1, self.groups[1], 1);
            if !o.probes.is_empty() {
                pass.set_pipeline(probe);
                pass.dispatch_workgroups((o.probes.len() as u32).div_ceil(GROUP_X), 1, 1);
            }
        }
        self.queue.submit([encoder.finish()]);
        let v: Vec<f64> = self.read::<T>(&o.results).iter().map(|x| x.f64()).collect();
        let (rows, probes) = v.split_at(4 * self.groups[1] as usize);
        Observation::from_partials(
            rows.chunks_exact(4).map(|r| [r[0], r[1], r[2], r[3]]),
            probes.chunks_exact(3).map(|p| (p[0], p[1], p[2])).collect(),
        )
    }

    /// The buffers and bind group of an observation of the `probes` cells.
    fn observer<T: Real>(&self, probes: Vec<u32>) -> Observer {
        let cells: Vec<u32> = std::iter::once(probes.len() as u32)
            .chain(probes.iter().copied())
            .collect();
        let values = 4 * self.groups[1] as usize + 3 * probes.len();
        let results = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("observation"),
            size: (values * std::mem::size_of::<T>()) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let cells = self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("probe cells"),
                contents: bytemuck::cast_slice(&cells),
                usage: wgpu::BufferUsages::STORAGE,
            });
        let group = self.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("observation"),
            layout: &self.observe_layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: results.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: cells.as_entire_binding(),
                },
            ],
        });
        Observer {
            probes,
            results,
            group,
        }
    }

    /// Copy the device's populations and parity into `lattice` (built like the uploaded one).
    pub fn download<T: Real>(&self, lattice: &mut Lattice<T>) {
        lattice.set_state(self.read(&self.buffers[F]), self.even);
    }

    /// The momentum each obstacle link exchanged in the last step (link order).
    pub fn exchanged<T: Real>(&self) -> Vec<f64> {
        let m: Vec<T> = self.read(&self.buffers[EXCHANGED]);
        m[..self.links as usize].iter().map(|v| v.f64()).collect()
    }

    /// Replace the device's populations and parity by `lattice`'s.
    pub fn upload<T: Real>(&mut self, lattice: &Lattice<T>) {
        let (pops, even) = lattice.state();
        self.queue
            .write_buffer(&self.buffers[F], 0, bytemuck::cast_slice(&pops));
        self.even = even;
    }
}

/// A fluid that steps on the GPU: [`Fluid`] over a [`GpuLattice`] and a host copy of the
/// solver, whose populations are refreshed from the device only for what needs the whole
/// lattice (fields, single cells, checkpoints) and whose obstacle loads only when asked for;
/// sums, probes and stability checks are reduced on the device ([`GpuLattice::observe`]).
pub struct GpuFluid<T> {
    host: RefCell<Lbm<T>>,
    device: GpuLattice,
    /// True when the device's populations are ahead of the host copy's …
    stale: Cell<bool>,
    /// … and its obstacle loads.
    stale_loads: Cell<bool>,
}

impl<T: Real> GpuFluid<T> {
    /// Move `lbm` onto the GPU. Fails with the reason for what the adapter lacks (see
    /// [`GpuLattice::new`]).
    pub fn new(gpu: &Gpu, lbm: Lbm<T>) -> std::result::Result<Self, String> {
        Self::with_term(gpu, lbm, None)
    }

    /// Move `lbm` onto the GPU with a coupling's `term` on the cells its solids cover (set
    /// through [`GpuFluid::lattice_mut`]).
    pub fn with_term(
        gpu: &Gpu,
        lbm: Lbm<T>,
        term: Option<&CoveredTerm>,
    ) -> std::result::Result<Self, String> {
        let device = GpuLattice::new(gpu, &lbm.lattice, &lbm.collider, &lbm.obstacles, term)?;
        Ok(GpuFluid {
            host: RefCell::new(lbm),
            device,
            stale: Cell::new(false),
            stale_loads: Cell::new(false),
        })
    }

    /// The host copy, brought up to date with the device (populations and the last step's
    /// obstacle loads).
    pub fn host(&self) -> Ref<'_, Lbm<T>> {
        if self.stale.get() {
            self.device.download(&mut self.host.borrow_mut().lattice);
            self.stale.set(false);
        }
        self.refresh_loads();
        self.host.borrow()
    }

    /// The solver back on the host, up to date.
    pub fn into_host(self) -> Lbm<T> {
        drop(self.host());
        self.host.into_inner()
    }

    /// The lattice on the device.
    pub fn lattice(&self) -> &GpuLattice {
        &self.device
    }

    /// The lattice on the device, to change its cover ([`GpuLattice::set_cover`]).
    pub fn lattice_mut(&mut self) -> &mut GpuLattice {
        &mut self.device
    }

    /// Bring the host copy's obstacle loads up to date (the per-link momenta only come back).
    fn refresh_loads(&self) {
        if self.stale_loads.get() {
            if self.device.links > 0 {
                let exchanged = self.device.exchanged::<T>();
                self.host.borrow_mut().obstacles.set_loads(&exchanged);
            }
            self.stale_loads.set(false);
        }
    }
}

impl<T: Real> Fluid for GpuFluid<T> {
    fn steps(&mut self, n: u64) {
        self.device.run(n);
        self.host.get_mut().steps += n;
        self.stale.set(true);
        self.stale_loads.set(true);
    }
    fn finish(&self) {
        self.device.finish()
    }
    fn step_count(&self) -> u64 {
        self.host.borrow().steps
    }
    fn units(&self) -> Units {
        self.host.borrow().units
    }
    fn macroscopic(&self, m: &mut Macroscopic) {
        self.host().macroscopic_into(m)
    }
    fn cell_state(&self, c: usize) -> (f64, f64, f64) {
        self.host().cell(c)
    }
    fn obstacle_loads(&self) -> (Vec<[f64; 2]>, Vec<f64>) {
        self.refresh_loads();
        let host = self.host.borrow();
        (host.obstacles.force.clone(), host.obstacles.torque.clone())
    }
    fn total_mass(&self) -> f64 {
        self.host().lattice.total_mass()
    }
    fn observe(&self, probes: &[usize]) -> Observation {
        self.device.observe::<T>(probes)
    }
    /// On the device's sums; only when they show a problem is the lattice read back, to name
    /// the first bad cell as the CPU does.
    fn check_stable(&self, max_mach: f64) -> Result<()> {
        if self.device.observe::<T>(&[]).is_stable(max_mach) {
            return Ok(());
        }
        Fluid::check_stable(&*self.host(), max_mach)
    }
    fn bytes(&self) -> usize {
        self.host.borrow().lattice.bytes()
    }
    fn precision(&self) -> &'static str {
        T::NAME
    }
    fn state(&self) -> LbmState {
        self.host().state()
    }
    fn set_state(&mut self, s: LbmState) -> Result<()> {
        let host = self.host.get_mut();
        host.set_state(s)?;
        self.device.upload(&host.lattice);
        self.stale.set(false);
        self.stale_loads.set(false);
        Ok(())
    }
}
