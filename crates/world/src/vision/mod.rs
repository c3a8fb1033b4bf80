//! Vision sensors: CPU rendering of RGB and depth images, and CoppeliaSim's
//! `simVision` work-image operations.
//!
//! # What a sensor sees
//! A perspective vision sensor ([`VisionModel`]) looks along its local +Z axis with
//! its local +Y up in the image; image right is therefore its local **-X**, as in
//! CoppeliaSim. The field of view spans the larger image side. Every visual of every
//! shape (the floor included) is tessellated once, cached, and rasterised with a
//! z-buffer; near and far planes clip geometry. Nothing else (dummies, joints,
//! drawing objects) is drawn.
//!
//! Shading: a pixel shows `colour * min(1, 0.3 + 0.45 |n·z_sensor| + 0.35 max(0, n·z_world))`,
//! that is, ambient light, a headlight along the viewing axis, and a light from
//! straight above, with normals interpolated over curved surfaces (Gouraud). Pixels
//! that see nothing between the clipping planes show the **background**: the sensor's
//! own colour ([`VisionModel::background`], CoppeliaSim's null-pixel colour), else the
//! scene's ([`SimSettings::background`](crate::scene::SimSettings::background),
//! CoppeliaSim's environment colour its sensors clear to), else black. Their depth is
//! 1 (the far plane), and a colour-coded image shows white there. A sensor's image is
//! black before its first render.
//!
//! # Image layout
//! Images are stored and exchanged as CoppeliaSim does: row-major, **bottom row first**
//! (OpenGL's `glReadPixels` order), left to right within a row. RGB images have 3 bytes
//! per pixel; depth has one `f32` per pixel holding the *planar* depth (distance along
//! the viewing axis) normalised between the clipping planes, `(z - near) / (far -
//! near)`, and 1 where nothing is seen. A client that wants a top-row-first image
//! flips the rows (`numpy.flipud`), as with CoppeliaSim.
//!
//! # When images are rendered
//! Rendering happens only when a sensor is *handled*:
//! - explicitly, through [`handle_vision_sensor`] (`sim.handleVisionSensor`, and the
//!   host for sensors with a `sysCall_vision` callback, before calling it). From the
//!   first explicit handling on, the sensor is **explicitly handled**: readers get the
//!   image of its last handling, however old, as CoppeliaSim returns the last acquired
//!   image;
//! - on demand by a *reader* (`sim.getVisionSensorImg`, `sim.getVisionSensorDepth`,
//!   `sim.readVisionSensor`, `simVision.sensorImgToWorkImg`, ...), for sensors that are
//!   not explicitly handled, when the image is older than the current simulation step.
//!   So a sensor nobody reads costs nothing, and one read many times per step renders
//!   once.
//!
//! Writing the image (`sim.setVisionSensorImg`, `simVision.workImgToSensorImg`) counts
//! as an image of the current step, so an edge image written by `sysCall_vision` is what
//! other scripts read until the sensor is handled again.

mod blobs;
// Public as a module (not re-exported), as `scan` below: it works on this module's work
// images.
pub mod buffers;
mod bytes;
mod closure;
mod detail;
mod raster;
#[cfg(test)]
mod render_tests;
mod resolve;
#[cfg(test)]
mod texture_tests;
// Public as a module (not re-exported) because it reads this module's work images: a
// re-export would make the two files import each other.
pub mod scan;
mod simd;
mod tessellate;
mod texturing;
mod twin;
mod viewer_parts;
mod work_image;

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::SimError;
use crate::scene::VisionModel;
use crate::world::{Handle, ObjectKind, World};

/// Largest image side rendered, in pixels (the scene loader enforces the same limit).
pub use crate::scene::MAX_VISION_RESOLUTION as MAX_RESOLUTION;
pub use viewer_parts::{TexturedPart, textured_parts};

/// Rendered images and work images of every vision sensor, by handle, plus the
/// renderer's caches (tessellated shapes, reusable buffers).
#[derive(Debug, Clone, Default)]
pub struct VisionStates {
    sensors: BTreeMap<Handle, SensorImage>,
    shapes: raster::ShapeCache,
    scratch: raster::Scratch,
    /// The calling thread's frame buffers, for the sensors it draws whole.
    frame: raster::FrameBuffers,
    /// Buffers of the threads other than the caller's when sensors are drawn on
    /// several ([`VisionStates::render_many`]).
    extra_scratch: Vec<(raster::Scratch, raster::FrameBuffers)>,
    /// Frame buffers of the sensors drawn in bands (at most one fewer than the
    /// threads): with the threads' own, memory follows the threads and the largest
    /// sensor, not the number of sensors.
    frames: Vec<raster::FrameBuffers>,
    /// Draw every chunk, culling nothing: only for the test that culling changes no
    /// image (false, culling on, otherwise).
    no_cull: bool,
    /// Draw every mesh in full: only for the test that coarser levels stay within
    /// their error (false otherwise).
    full_detail: bool,
    /// Cut images of any size into bands: only for the test that bands change no
    /// image, whose sensors are small (false: see [`BandSizes`]).
    band_every_size: bool,
    /// Draw both faces of every imported mesh: only for the test that culling the back
    /// faces of their closed parts changes no pixel away from silhouettes (false
    /// otherwise).
    two_sided_meshes: bool,
    /// The last sensor rendered alone, for a colour-coded twin of it (`twin.rs`).
    last_view: twin::LastView,
}

/// The image state of one vision sensor.
#[derive(Debug, Clone)]
pub struct SensorImage {
    resolution: [u32; 2],
    rgb: Vec<u8>,
    depth: Vec<f32>,
    renders: u64,
    rendered: Option<RenderStamp>,
    /// Simulation step of the last write of `rgb` (render or set); `None` before any.
    image_step: Option<u64>,
    explicit: bool,
    work: Option<Work>,
    /// Scratch image of the 3x3 filters, kept to avoid an allocation per call.
    filter_scratch: Vec<f32>,
    /// simVision's buffers 1 and 2 (float RGB like the work image; empty until
    /// written, and read as black): see `buffers.rs`.
    buffers: [Vec<f32>; 2],
    result: Option<VisionResult>,
    /// Handle of the shape seen per pixel, -1 where none, bottom row first: empty until
    /// a mask is first asked for ([`read_mask`]), then drawn with every render.
    mask: Vec<i32>,
    /// Whether renders draw the mask (from the first [`read_mask`] on).
    mask_wanted: bool,
    /// Whether `mask` belongs to the last render.
    mask_current: bool,
    /// How long the last render took to draw (ns, all its bands): what the next
    /// schedules sensors by ([`VisionStates::render_many`]).
    draw_nanos: u64,
}

/// When a sensor last rendered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderStamp {
    /// Completed simulation steps at the time ([`World::steps`]).
    pub step: u64,
    /// Simulation time, s ([`World::time`]).
    pub time: f64,
}

/// The detection state `sim.readVisionSensor` reports.
#[derive(Debug, Clone, PartialEq)]
pub struct VisionResult {
    /// Whether the sensor triggered (set by the `sysCall_vision` callback's `trigger`).
    pub trigger: bool,
    /// Auxiliary packets: packet 1 is CoppeliaSim's 15 default values (minimum,
    /// maximum and average of intensity, red, green, blue and normalised depth, each
    /// 0..1), followed by the callback's packets.
    pub packets: Vec<Vec<f64>>,
}

impl SensorImage {
    fn new(resolution: [u32; 2]) -> Self {
        let n = resolution[0] as usize * resolution[1] as usize;
        SensorImage {
            resolution,
            rgb: vec![0; 3 * n],
            depth: vec![1.0; n],
            renders: 0,
            rendered: None,
            image_step: None,
            explicit: false,
            work: None,
            filter_scratch: Vec::new(),
            buffers: [Vec::new(), Vec::new()],
            result: None,
            mask: Vec::new(),
            mask_wanted: false,
            mask_current: false,
            draw_nanos: 0,
        }
    }

    /// A new black image for a sensor whose resolution changed, which keeps drawing
    /// masks if it did.
    fn resized(old: &SensorImage, resolution: [u32; 2]) -> Self {
        SensorImage {
            mask_wanted: old.mask_wanted,
            ..SensorImage::new(resolution)
        }
    }

    /// `[width, height]` in pixels.
    pub fn resolution(&self) -> [u32; 2] {
        self.resolution
    }

    /// The sensor image: RGB, 3 bytes per pixel, bottom row first. After
    /// `simVision.workImgToSensorImg` or `sim.setVisionSensorImg` this is the written
    /// image, not the rendered one.
    pub fn rgb(&self) -> &[u8] {
        &self.rgb
    }

    /// Depth of the last render: planar depth normalised to 0..1 between the clipping
    /// planes, one value per pixel, bottom row first.
    pub fn depth(&self) -> &[f32] {
        &self.depth
    }

    /// The segmentation mask of the last render: per pixel, the handle of the shape
    /// seen (-1 where nothing is), bottom row first. `None` when the last render drew
    /// none (before the first [`read_mask`], which turns masks on).
    pub fn mask(&self) -> Option<&[i32]> {
        self.mask_current.then_some(self.mask.as_slice())
    }

    /// How many times the sensor rendered since the scene was loaded.
    pub fn renders(&self) -> u64 {
        self.renders
    }

    /// When it last rendered, `None` if never.
    pub fn rendered(&self) -> Option<RenderStamp> {
        self.rendered
    }

    /// The simVision work image (RGB `f32`, nominally 0..1, bottom row first), if one
    /// was created by `simVision.sensorImgToWorkImg` and not yet removed. A copy: the
    /// image is kept in a compact form (`Work`).
    pub fn work_image(&self) -> Option<Vec<f32>> {
        self.work.as_ref().map(Work::to_floats)
    }

    /// The detection state, `None` before the sensor was first handled.
    pub fn result(&self) -> Option<&VisionResult> {
        self.result.as_ref()
    }

    fn size(&self) -> (usize, usize) {
        (self.resolution[0] as usize, self.resolution[1] as usize)
    }

    /// Whether a render with `cam` draws the mask: once one was asked for, and for a
    /// colour-coded image, which draws the handles anyway (its mask costs one copy).
    fn mask_wanted_now(&self, cam: &raster::Camera) -> bool {
        self.mask_wanted || cam.colour == raster::ColourWork::Coded
    }
}

impl VisionStates {
    /// The image state of sensor `h`, `None` until it was first rendered or written.
    pub fn image(&self, h: Handle) -> Option<&SensorImage> {
        self.sensors.get(&h)
    }

    /// How many times sensor `h` rendered (0 if never).
    pub fn render_count(&self, h: Handle) -> u64 {
        self.sensors.get(&h).map_or(0, |s| s.renders)
    }

    /// Records what a `sysCall_vision` callback returned for sensor `h`: its `trigger`
    /// and its packets (already unpacked, e.g. with [`unpack_floats`]), which follow
    /// packet 1 in `sim.readVisionSensor` and `sim.handleVisionSensor`.
    ///
    /// # Errors
    /// [`SimError::BadArgument`] if the sensor was never handled.
    pub fn set_callback_result(&mut self, h: Handle, trigger: bool, packets: Vec<Vec<f64>>) -> Result<(), SimError> {
        let result = self
            .sensors
            .get_mut(&h)
            .and_then(|s| s.result.as_mut())
            .ok_or_else(|| SimError::BadArgument(format!("vision sensor {h} was not handled yet")))?;
        result.trigger = trigger;
        result.packets.truncate(1);
        result.packets.extend(packets);
        Ok(())
    }

    /// Mutable state of sensor `h`, created (black, no render) with the model's
    /// resolution if needed.
    fn state_mut(&mut self, h: Handle, model: &VisionModel) -> &mut SensorImage {
        let s = self
            .sensors
            .entry(h)
            .or_insert_with(|| SensorImage::new(model.resolution));
        if s.resolution != model.resolution {
            *s = SensorImage::resized(s, model.resolution);
        }
        s
    }

    fn render(&mut self, world: &World, h: Handle) -> Result<(), SimError> {
        // One handle in, one outcome out.
        self.render_many(world, &[h], cores()).pop().unwrap_or(Ok(()))
    }

    /// Renders the sensors `handles` on up to `threads` threads (the calling one
    /// included) and returns each one's outcome, in order. Each pixel depends only on
    /// the world and the sensor, never on the thread, the band of rows or the order it
    /// was drawn in, so the images are the same bits however many threads draw them.
    fn render_many(&mut self, world: &World, handles: &[Handle], threads: usize) -> Vec<Result<(), SimError>> {
        self.shapes.refresh(world);
        let VisionStates {
            sensors,
            shapes,
            scratch,
            frame,
            extra_scratch,
            frames,
            no_cull,
            full_detail,
            band_every_size,
            two_sided_meshes,
            last_view,
        } = self;
        let shortcuts = raster::Shortcuts {
            cull: !*no_cull,
            coarse: !*full_detail,
            mesh_back_faces: !*two_sided_meshes,
        };
        // Each job owns its sensor's image while it is drawn: taken out of the map here,
        // put back below.
        let mut jobs = Vec::new();
        let mut outcomes: Vec<Result<(), SimError>> = Vec::with_capacity(handles.len());
        for &h in handles {
            let prepared = sensor_model(world, h).and_then(|(model, pose)| {
                let cam = camera(h, model)?.with_scene_background(model, world.settings().background);
                Ok((cam, model, pose))
            });
            match prepared {
                Ok((cam, model, pose)) => {
                    let mut s = sensors.remove(&h).unwrap_or_else(|| SensorImage::new(model.resolution));
                    if s.resolution != model.resolution {
                        s = SensorImage::resized(&s, model.resolution);
                    }
                    jobs.push(Job {
                        handle: h,
                        cam,
                        pose,
                        image: s,
                        packet1: [0.0; 15],
                        nanos: AtomicU64::new(0),
                    });
                    outcomes.push(Ok(()));
                }
                Err(e) => outcomes.push(Err(e)),
            }
        }
        let items = raster::draw_list(world, shapes);
        // A sensor rendered alone (PyRep's `handle_explicitly`): a colour-coded twin of
        // the view rendered just before takes its buffers (`twin.rs`).
        let single = match jobs.as_mut_slice() {
            [job] => {
                if last_view.has_twin(job.handle) {
                    job.image.mask_wanted = true;
                }
                Some(twin::ViewKey::new(world, &job.cam, &job.pose, &items))
            }
            _ => None,
        };
        let mut reused = false;
        if let (Some(key), [job]) = (&single, jobs.as_mut_slice())
            && job.cam.colour == raster::ColourWork::Coded
        {
            match last_view.check(key) {
                twin::TwinOutcome::Reuse => {
                    job.prepare();
                    last_view.load(&job.cam, frame);
                    job.finish(frame);
                    reused = true;
                }
                twin::TwinOutcome::DrawAndTeach(source) => {
                    if let Some(s) = sensors.get_mut(&source) {
                        s.mask_wanted = true;
                    }
                }
                twin::TwinOutcome::Draw => {}
            }
        }
        if !reused {
            // What each thread takes from the queue: a whole sensor, or a band of one. The
            // costliest sensors of the last frame first, and the cheapest cut into bands
            // (see `bands_per_sensor`), so that the threads finish together: the longest
            // processing time first, then the small pieces. Only the schedule depends on
            // these timings, never a pixel.
            jobs.sort_by_key(|job| std::cmp::Reverse(job.image.draw_nanos));
            let sizes = if *band_every_size {
                BandSizes::ANY
            } else {
                BandSizes::DEFAULT
            };
            let bands = bands_per_sensor(&jobs, threads, sizes);
            frames.resize_with(
                bands.iter().filter(|&&count| count > 1).count(),
                raster::FrameBuffers::default,
            );
            let mut units = Vec::new();
            let mut banded_frames = frames.iter_mut();
            for (job, &count) in jobs.iter_mut().zip(&bands) {
                job.prepare();
                if count == 1 {
                    units.push(Unit::Whole(job));
                } else if let Some(buffers) = banded_frames.next() {
                    let job = &*job;
                    let mask = job.image.mask_wanted_now(&job.cam);
                    units.extend(
                        buffers
                            .bands(&job.cam, mask, count)
                            .into_iter()
                            .map(|band| Unit::Band(job, band)),
                    );
                }
            }
            let threads = threads.clamp(1, units.len().max(1));
            let draw = |unit: Unit<'_>, scratch: &mut raster::Scratch, frame: &mut raster::FrameBuffers| {
                let start = std::time::Instant::now();
                let draw_band = |job: &Job, band, scratch: &mut raster::Scratch| {
                    raster::draw_band(&items, &job.cam, &job.pose, scratch, band, shortcuts);
                };
                let nanos = |start: std::time::Instant| u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
                match unit {
                    Unit::Whole(job) => {
                        // In this thread's own buffers, and finished here too.
                        let mask = job.image.mask_wanted_now(&job.cam);
                        for band in frame.bands(&job.cam, mask, 1) {
                            draw_band(job, band, scratch);
                        }
                        job.image.draw_nanos = nanos(start);
                        job.finish(frame);
                    }
                    Unit::Band(job, band) => {
                        draw_band(job, band, scratch);
                        job.nanos.fetch_add(nanos(start), Ordering::Relaxed);
                    }
                }
            };
            if threads == 1 {
                for unit in units {
                    draw(unit, scratch, frame);
                }
            } else {
                // Each thread takes the next unit not yet drawn, this one included: views
                // of one scene can differ several-fold in cost (a camera close to a mesh
                // arm against one far away), and dealing them out in fixed runs left one
                // core idle while the other drew three. The bands come last, so that they
                // even out the end. A thread costs 20-50 us to start on the 2-core VM,
                // less than one 128 x 128 frame of a scene with a mesh arm in view (a
                // lone small sensor is not cut, and so starts none: `BandSizes`).
                extra_scratch.resize_with(threads - 1, Default::default);
                let queue = std::sync::Mutex::new(units.into_iter());
                let next = || queue.lock().ok().and_then(|mut q| q.next());
                let draw_queue = |scratch: &mut raster::Scratch, frame: &mut raster::FrameBuffers| {
                    while let Some(unit) = next() {
                        draw(unit, scratch, frame);
                    }
                };
                std::thread::scope(|scope| {
                    for (scratch, frame) in extra_scratch.iter_mut() {
                        scope.spawn(|| draw_queue(scratch, frame));
                    }
                    draw_queue(scratch, frame);
                });
            }
            // The sensors drawn in bands: their last pass, now that every band is drawn.
            let mut banded_frames = frames.iter_mut();
            for (job, &count) in jobs.iter_mut().zip(&bands) {
                if count > 1
                    && let Some(buffers) = banded_frames.next()
                {
                    job.finish(buffers);
                    job.image.draw_nanos = *job.nanos.get_mut();
                }
            }
            match (single, jobs.as_slice()) {
                (Some(key), [job]) => {
                    // Drawn whole in this thread's buffers, or in bands in the first banded ones.
                    let drawn = if bands.first().is_some_and(|&count| count > 1) {
                        frames.first()
                    } else {
                        Some(&*frame)
                    };
                    match drawn {
                        Some(buffers) => last_view.remember(key, job.handle, buffers, job.cam.width * job.cam.height),
                        None => last_view.forget(),
                    }
                }
                _ => last_view.forget(),
            }
        }
        for job in jobs {
            let mut s = job.image;
            s.renders += 1;
            s.rendered = Some(RenderStamp {
                step: world.steps(),
                time: world.time(),
            });
            s.image_step = Some(world.steps());
            s.result = Some(VisionResult {
                trigger: false,
                packets: vec![job.packet1.to_vec()],
            });
            sensors.insert(job.handle, s);
        }
        outcomes
    }
}

/// One sensor to render in [`VisionStates::render_many`].
struct Job {
    handle: Handle,
    cam: raster::Camera,
    /// The sensor's world pose.
    pose: crate::math::Pose,
    image: SensorImage,
    packet1: resolve::Packet1,
    /// Time spent drawing its bands (ns), summed over the threads.
    nanos: AtomicU64,
}

/// What one thread takes from the queue in [`VisionStates::render_many`]: a whole
/// sensor, drawn in the thread's own frame buffers and finished there, or a band of one
/// (in buffers of its sensor's), finished once all its bands are drawn.
enum Unit<'a> {
    Whole(&'a mut Job),
    Band(&'a Job, raster::Band<'a>),
}

impl Job {
    /// Sizes the mask buffer when this frame draws one.
    fn prepare(&mut self) {
        if self.image.mask_wanted_now(&self.cam) {
            self.image.mask.resize(self.image.depth.len(), -1);
        }
    }

    /// The sensor image and packet 1 from the drawn `buffers`.
    fn finish(&mut self, buffers: &mut raster::FrameBuffers) {
        let image = &mut self.image;
        let with_mask = image.mask_wanted_now(&self.cam);
        let frame = raster::Frame {
            rgb: &mut image.rgb,
            depth: &mut image.depth,
            mask: with_mask.then_some(image.mask.as_mut_slice()),
        };
        self.packet1 = raster::finish(&self.cam, buffers, frame);
        image.mask_current = with_mask;
    }
}

/// How many bands of rows each of `jobs` is cut into for `threads` threads: as many
/// whole sensors as share out evenly, and the rest (the last `jobs % threads`, the
/// cheapest as [`VisionStates::render_many`] orders them) in
/// `threads` bands each, when a band still has `min.band` pixels. A band costs its
/// share of the fill but all the culling and vertex work of the geometry in its rows,
/// so whole sensors are the cheaper unit where they balance. A sensor drawn alone is
/// cut only from `min.alone` pixels on.
fn bands_per_sensor(jobs: &[Job], threads: usize, min: BandSizes) -> Vec<usize> {
    let threads = threads.max(1);
    let whole = jobs.len() - jobs.len() % threads;
    let alone = if jobs.len() == 1 { min.alone } else { 0 };
    jobs.iter()
        .enumerate()
        .map(|(k, job)| {
            let pixels = job.cam.width * job.cam.height;
            if k < whole || pixels < min.band * threads || pixels < alone {
                1
            } else {
                threads
            }
        })
        .collect()
}

/// The smallest images [`bands_per_sensor`] cuts into bands.
#[derive(Debug, Clone, Copy)]
struct BandSizes {
    /// Pixels of a band, when threads are started anyway for several sensors.
    band: usize,
    /// Pixels of a sensor drawn alone.
    alone: usize,
}

impl BandSizes {
    /// A thread costs 20-50 us to start on the 2-core VM and a 256 x 256 frame of a
    /// simple scene takes 0.1-0.25 ms: measured (vision bench, BubbleRob), two bands of
    /// it alone were slower than one, while a 640 x 480 frame with a mesh arm (4-5 ms)
    /// gains.
    const DEFAULT: BandSizes = BandSizes {
        band: 64 * 64,
        alone: 1 << 17,
    };
    /// Any image: for the test that bands change no bit.
    const ANY: BandSizes = BandSizes { band: 1, alone: 0 };
}

/// The cores rendering may use, asked once per process: on Linux
/// `available_parallelism` reads the cgroup files in `/proc` and `/sys` each time,
/// 20-40 us, as long as a 1 x 1 frame.
fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, usize::from))
}

/// The vision model and world pose of sensor `h`.
pub fn sensor_model(world: &World, h: Handle) -> Result<(&VisionModel, crate::math::Pose), SimError> {
    let o = world.object(h)?;
    match &o.kind {
        ObjectKind::VisionSensor(m) => {
            // Validated here, before any buffer of the model's size is allocated.
            camera(h, m)?;
            Ok((m, o.world))
        }
        other => Err(SimError::WrongKind {
            handle: h,
            expected: "vision sensor",
            actual: other.name(),
        }),
    }
}

/// The renderer's camera for a sensor model.
///
/// # Errors
/// [`SimError::BadArgument`] for a model out of range (resolution, view angle or
/// clipping planes).
fn camera(h: Handle, m: &VisionModel) -> Result<raster::Camera, SimError> {
    raster::Camera::new(m, MAX_RESOLUTION).ok_or_else(|| {
        SimError::BadArgument(format!(
            "vision sensor {h}: resolution {}x{} must be 1..={MAX_RESOLUTION} per side, with 0 < view angle < pi \
             and 0 < near < far",
            m.resolution[0], m.resolution[1]
        ))
    })
}

/// Renders sensor `h` now, whatever the age of its image, and makes it explicitly
/// handled (see the module docs). Resets its detection state to "not triggered" with
/// packet 1 of the new image. The host calls this before a sensor's `sysCall_vision`.
///
/// # Errors
/// No such object, not a vision sensor, or a sensor model out of range.
pub fn handle_vision_sensor(world: &World, states: &mut VisionStates, h: Handle) -> Result<(), SimError> {
    states.render(world, h)?;
    if let Some(s) = states.sensors.get_mut(&h) {
        s.explicit = true;
    }
    Ok(())
}

/// Makes sensor `h` explicitly handled, or not, without rendering it (CoppeliaSim's
/// explicit-handling flag: `sim.setExplicitHandling`, `sim.createVisionSensor`'s option
/// bit 0). An explicitly handled sensor renders only when handled, and its readers get
/// its last image (black before the first); one that is not renders when read.
///
/// # Errors
/// No such object or not a vision sensor.
pub fn set_explicit(world: &World, states: &mut VisionStates, h: Handle, explicit: bool) -> Result<(), SimError> {
    state(world, states, h)?.explicit = explicit;
    Ok(())
}

/// Whether sensor `h` is explicitly handled (see [`set_explicit`]); false for a sensor
/// that never rendered nor was flagged.
pub fn is_explicit(states: &VisionStates, h: Handle) -> bool {
    states.sensors.get(&h).is_some_and(|s| s.explicit)
}

/// Renders every vision sensor (`sim.handle_all`), or only those not explicitly handled
/// (`sim.handle_all_except_explicit`); returns how many rendered. Does not make them
/// explicitly handled. Several sensors are drawn on as many threads as there are cores,
/// with the same images as one after the other.
///
/// # Errors
/// The first sensor that fails to render (the others still render).
pub fn handle_all_vision_sensors(
    world: &World,
    states: &mut VisionStates,
    except_explicit: bool,
) -> Result<usize, SimError> {
    let sensors: Vec<Handle> = world
        .handles()
        .iter()
        .copied()
        .filter(|&h| matches!(world.object(h).map(|o| &o.kind), Ok(ObjectKind::VisionSensor(_))))
        .filter(|h| !except_explicit || !states.sensors.get(h).is_some_and(|s| s.explicit))
        .collect();
    let mut first_error = None;
    let mut count = 0;
    for outcome in states.render_many(world, &sensors, cores()) {
        match outcome {
            Ok(()) => count += 1,
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    first_error.map_or(Ok(count), Err)
}

/// A reader's access: renders sensor `h` if it is not explicitly handled and its image
/// is older than the current step, then returns its state.
///
/// # Errors
/// As [`handle_vision_sensor`].
pub fn read<'a>(world: &World, states: &'a mut VisionStates, h: Handle) -> Result<&'a mut SensorImage, SimError> {
    let (model, _) = sensor_model(world, h)?;
    let step = world.steps();
    let stale = match states.sensors.get(&h) {
        Some(s) => (!s.explicit && s.image_step.is_none_or(|at| at < step)) || s.resolution != model.resolution,
        None => true,
    };
    if stale {
        states.render(world, h)?;
    }
    let (&model, _) = sensor_model(world, h)?;
    Ok(states.state_mut(h, &model))
}

/// A mask reader's access (`sim.getVisionSensorMask`): as [`read`], and if the image
/// has no mask, the sensor renders again now with one (explicitly handled sensors
/// too, so that image, depth and mask stay of one instant). From then on every render
/// of the sensor draws its mask, at the cost of one more buffer write per pixel drawn.
///
/// # Errors
/// As [`handle_vision_sensor`].
pub fn read_mask<'a>(world: &World, states: &'a mut VisionStates, h: Handle) -> Result<&'a SensorImage, SimError> {
    // Wanted before reading, so that a stale image renders once, with its mask.
    state(world, states, h)?.mask_wanted = true;
    if !read(world, states, h)?.mask_current {
        states.render(world, h)?;
    }
    state(world, states, h).map(|s| &*s)
}

/// The sensor's state without rendering, created black if it never rendered.
///
/// # Errors
/// No such object or not a vision sensor.
pub fn state<'a>(world: &World, states: &'a mut VisionStates, h: Handle) -> Result<&'a mut SensorImage, SimError> {
    let (&model, _) = sensor_model(world, h)?;
    Ok(states.state_mut(h, &model))
}

/// A writer's access (`sim.setVisionSensorImg`): like [`state`], and the image then
/// counts as an image of the current step.
///
/// # Errors
/// No such object or not a vision sensor.
pub fn write<'a>(world: &World, states: &'a mut VisionStates, h: Handle) -> Result<&'a mut SensorImage, SimError> {
    let step = world.steps();
    let s = state(world, states, h)?;
    s.image_step = Some(step);
    Ok(s)
}

/// `simVision.workImgToSensorImg`: writes the work image (clamped to 0..1) into the
/// sensor image, which then counts as an image of the current step, and drops the
/// work image if `remove`.
///
/// # Errors
/// No such object, not a vision sensor, or no work image.
pub fn work_to_sensor(world: &World, states: &mut VisionStates, h: Handle, remove: bool) -> Result<(), SimError> {
    let step = world.steps();
    let s = state(world, states, h)?;
    let Some(work) = &s.work else {
        return Err(no_work_image(h));
    };
    work.write_bytes(&mut s.rgb);
    if remove {
        s.work = None;
    }
    s.image_step = Some(step);
    Ok(())
}

fn no_work_image(h: Handle) -> SimError {
    SimError::BadArgument(format!(
        "vision sensor {h} has no work image: call simVision.sensorImgToWorkImg first"
    ))
}

/// Work-image access for `simVision` functions other than `sensorImgToWorkImg`.
///
/// # Errors
/// No such object, not a vision sensor, or no work image.
pub fn work<'a>(world: &World, states: &'a mut VisionStates, h: Handle) -> Result<WorkImage<'a>, SimError> {
    let (&model, _) = sensor_model(world, h)?;
    let s = states.state_mut(h, &model);
    let (width, height) = s.size();
    match &mut s.work {
        Some(work) => Ok(WorkImage {
            width,
            height,
            work,
            scratch: &mut s.filter_scratch,
            buffers: &mut s.buffers,
        }),
        None => Err(no_work_image(h)),
    }
}

/// A work image as CoppeliaSim defines it: float RGB, nominally 0..1, bottom row
/// first. It is kept in the cheapest form that holds its exact values, because the
/// flow scripts use most, sensor image → edge detection → sensor image at every step,
/// never needs the floats: a copy of the sensor's bytes and an edge image hold the
/// same values as the float image in a quarter and a twelfth of the memory, and
/// moving 800 KB of floats per operation was most of that flow's time.
#[derive(Debug, Clone)]
enum Work {
    /// RGB bytes; each value is `byte / 255`.
    Bytes(Vec<u8>),
    /// One byte per pixel, 0 or 1, the same in R, G and B.
    Binary(Vec<u8>),
    /// Any values.
    Float(Vec<f32>),
}

impl Work {
    /// The values as float RGB.
    fn to_floats(&self) -> Vec<f32> {
        match self {
            Work::Bytes(b) => b.iter().map(|&c| f32::from(c) / 255.0).collect(),
            Work::Binary(m) => m.iter().flat_map(|&v| [f32::from(v); 3]).collect(),
            Work::Float(f) => f.clone(),
        }
    }

    /// Switches to the float form (for the operations that need it) and returns it.
    fn floats_mut(&mut self) -> &mut Vec<f32> {
        if !matches!(self, Work::Float(_)) {
            *self = Work::Float(self.to_floats());
        }
        match self {
            Work::Float(f) => f,
            // Just made the float form.
            Work::Bytes(_) | Work::Binary(_) => unreachable!("work image converted to floats above"),
        }
    }

    /// Per pixel, R + G + B, in units where a channel at 1.0 counts as the returned
    /// scale. For bytes that is 255: the sums are then small integers, exact in `f32`,
    /// and so is the edge filter over them (no division per value, no rounding).
    #[inline]
    fn grey_sums(&self, out: &mut [f32]) -> f32 {
        match self {
            Work::Bytes(b) => {
                for (g, px) in out.iter_mut().zip(b.as_chunks::<3>().0) {
                    *g = f32::from(u16::from(px[0]) + u16::from(px[1]) + u16::from(px[2]));
                }
                255.0
            }
            Work::Binary(m) => {
                for (g, &v) in out.iter_mut().zip(m) {
                    *g = 3.0 * f32::from(v);
                }
                1.0
            }
            Work::Float(f) => {
                for (g, px) in out.iter_mut().zip(f.as_chunks::<3>().0) {
                    *g = px[0] + px[1] + px[2];
                }
                1.0
            }
        }
    }

    /// `simVision.workImgToSensorImg`'s conversion: each value times 255, rounded,
    /// clamped to 0..255 (NaN → 0), as CoppeliaSim does.
    fn write_bytes(&self, rgb: &mut [u8]) {
        match self {
            // byte / 255 * 255 rounds back to the byte (tested for all 256).
            Work::Bytes(b) => rgb.copy_from_slice(b),
            // Each pixel black (0) or white (0xffffff).
            Work::Binary(m) => bytes::write_mask_rgb(m, rgb),
            Work::Float(f) => {
                for (c, &v) in rgb.iter_mut().zip(f) {
                    *c = bytes::round_byte(v * 255.0);
                }
            }
        }
    }
}

simd::multiversion! {
    /// [`WorkImage::edge_detection`] on a `width` x `height` image; `scratch` holds
    /// the grey image, then the filter's scratch. Twice as fast with AVX2 (see
    /// [`simd`]).
    fn edge_detection(width: usize, height: usize, work: &mut Work, scratch: &mut [f32], threshold: f32) {
        let (grey, rest) = scratch.split_at_mut((width * height).min(scratch.len()));
        let scale = work.grey_sums(grey);
        // The byte buffer of the old form becomes the mask: no allocation per frame.
        let mut mask = match std::mem::replace(work, Work::Binary(Vec::new())) {
            Work::Binary(m) | Work::Bytes(m) => m,
            Work::Float(_) => Vec::new(),
        };
        work_image::edge_mask(width, height, grey, rest, threshold * scale, &mut mask);
        *work = Work::Binary(mask);
    }
}

/// A sensor's work image lent to a `simVision` operation.
pub struct WorkImage<'a> {
    width: usize,
    height: usize,
    work: &'a mut Work,
    scratch: &'a mut Vec<f32>,
    buffers: &'a mut [Vec<f32>; 2],
}

impl WorkImage<'_> {
    /// `simVision.edgeDetectionOnWorkImg`: the result is black and white, so it is
    /// kept as `Work::Binary`.
    pub fn edge_detection(&mut self, threshold: f32) {
        let n = self.width * self.height;
        // The grey image, then the filter's scratch. Everything in it is overwritten,
        // so the buffer only grows and is never cleared: this runs at every step.
        let len = n + work_image::edge_scratch_len(self.width, self.height);
        if self.scratch.len() < len {
            self.scratch.resize(len, 0.0);
        }
        edge_detection(self.width, self.height, self.work, &mut self.scratch[..len], threshold);
    }

    /// `simVision.sharpenWorkImg`.
    pub fn sharpen(&mut self) {
        work_image::sharpen(self.width, self.height, self.work.floats_mut(), self.scratch);
    }

    /// `simVision.horizontalFlipWorkImg`.
    pub fn flip_horizontal(&mut self) {
        work_image::flip_horizontal(self.width, self.work.floats_mut());
    }

    /// `simVision.verticalFlipWorkImg`.
    pub fn flip_vertical(&mut self) {
        work_image::flip_vertical(self.width, self.height, self.work.floats_mut());
    }

    /// `simVision.selectiveColorOnWorkImg`: blacks out the pixels that do not match
    /// `color` within `tolerance` (with `keep`), or those that do (without); in RGB, or
    /// in HSL when `rgb` is false. See `blobs::selective_color`.
    /// (`removedPartToBuffer1` is in `buffers.rs`.)
    pub fn selective_color(&mut self, color: [f32; 3], tolerance: [f32; 3], rgb: bool, keep: bool) {
        blobs::selective_color(self.work.floats_mut(), color, tolerance, rgb, keep, None);
    }

    /// `simVision.blobDetectionOnWorkImg`: the packet of the blobs of pixels whose mean
    /// of R, G, B is at least `threshold`, blobs under `min_size` (a fraction of the
    /// image's pixels) left out and blacked out; with `recolor`, the background turns
    /// black and each blob takes a colour; with `overlay`, each blob's rectangle is
    /// drawn in that colour. See `blobs::blob_packet` for the packet.
    pub fn blob_detection(
        &mut self,
        threshold: f32,
        min_size: f64,
        recolor: bool,
        overlay: Option<[f32; 3]>,
    ) -> Vec<f32> {
        let options = blobs::BlobOptions {
            threshold,
            min_size,
            recolor,
            overlay,
        };
        let found = blobs::detect_blobs(self.width, self.height, self.work.floats_mut(), options);
        blobs::blob_packet(self.width, self.height, &found)
    }
}

impl SensorImage {
    /// `simVision.sensorImgToWorkImg`: the sensor image as floats 0..1 (kept as its
    /// bytes, see `Work`).
    pub fn rgb_to_work(&mut self) {
        // The buffer of a byte or edge image is reused: no allocation per frame.
        let mut bytes = match self.work.take() {
            Some(Work::Bytes(b) | Work::Binary(b)) => b,
            _ => Vec::new(),
        };
        bytes.clear();
        bytes.extend_from_slice(&self.rgb);
        self.work = Some(Work::Bytes(bytes));
    }

    /// `simVision.sensorDepthMapToWorkImg`: normalised depth as grey levels.
    pub fn depth_to_work(&mut self) {
        let floats = self.depth.iter().flat_map(|&d| [d; 3]).collect();
        self.work = Some(Work::Float(floats));
    }

    /// `simVision.uniformImgToWorkImg`: a work image of one colour.
    pub fn uniform_work(&mut self, color: [f32; 3]) {
        let n = self.depth.len();
        self.work = Some(Work::Float((0..n).flat_map(|_| color).collect()));
    }

    /// Mutable RGB bytes, for `sim.setVisionSensorImg`.
    pub fn rgb_mut(&mut self) -> &mut [u8] {
        &mut self.rgb
    }
}

/// Unpacks a CoppeliaSim packed float table (`sim.packFloatTable`: little-endian
/// `f32`s) such as a `sysCall_vision` packet. Trailing bytes that do not make a whole
/// float are ignored.
pub fn unpack_floats(bytes: &[u8]) -> Vec<f64> {
    bytes
        .chunks_exact(4)
        .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_survive_the_trip_through_floats() {
        // What makes `Work::Bytes` → sensor image a plain copy.
        for c in 0..=255u8 {
            assert_eq!(bytes::round_byte(f32::from(c) / 255.0 * 255.0), c);
        }
    }

    /// Pseudo-random RGB bytes.
    fn noise(n: usize, mut x: u64) -> Vec<u8> {
        (0..n)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 40) as u8
            })
            .collect()
    }

    #[test]
    fn compact_work_images_give_the_same_results_as_floats() {
        let (w, h) = (23, 17);
        for seed in [1u64, 0xdead_beef, 42] {
            let rgb = noise(3 * w * h, seed);
            let compact = Work::Bytes(rgb.clone());
            let float = Work::Float(compact.to_floats());
            assert_eq!(
                compact.to_floats(),
                rgb.iter().map(|&c| f32::from(c) / 255.0).collect::<Vec<_>>()
            );
            // Edge detection from either form, then back to bytes.
            let mut results = Vec::new();
            for mut work in [compact.clone(), float] {
                let mut scratch = Vec::new();
                WorkImage {
                    width: w,
                    height: h,
                    work: &mut work,
                    scratch: &mut scratch,
                    buffers: &mut Default::default(),
                }
                .edge_detection(0.2);
                assert!(matches!(work, Work::Binary(_)));
                let mut out = vec![7u8; 3 * w * h];
                work.write_bytes(&mut out);
                assert!(out.iter().all(|&c| c == 0 || c == 255));
                // The same image through floats.
                let mut via_floats = vec![7u8; 3 * w * h];
                Work::Float(work.to_floats()).write_bytes(&mut via_floats);
                assert_eq!(out, via_floats);
                results.push(out);
            }
            // Bytes filter exact integers, floats round: they may only differ where
            // the filtered mean is within rounding of the threshold.
            let floats = compact.to_floats();
            let grey: Vec<f32> = floats.chunks_exact(3).map(|p| p[0] + p[1] + p[2]).collect();
            let mut scratch = vec![0.0; work_image::edge_scratch_len(w, h)];
            let mut mask = Vec::new();
            work_image::edge_mask(w, h, &grey, &mut scratch, 0.2, &mut mask);
            let filtered = &scratch[..w * h];
            for i in 0..w * h {
                if (filtered[i] / 3.0 - 0.2).abs() > 1e-4 {
                    assert_eq!(results[0][3 * i], results[1][3 * i], "pixel {i}: {}", filtered[i] / 3.0);
                }
            }
            // Bytes back to the sensor image unchanged, and operations that need floats
            // start from the same values.
            let mut out = vec![0u8; 3 * w * h];
            compact.write_bytes(&mut out);
            assert_eq!(out, rgb);
            let mut flipped = compact.clone();
            work_image::flip_horizontal(w, flipped.floats_mut());
            let mut reference = compact.to_floats();
            work_image::flip_horizontal(w, &mut reference);
            assert_eq!(flipped.to_floats(), reference);
        }
    }
}
