//! A background sorter thread for the viewer: the render loop posts the newest camera and
//! draws with the newest *finished* order, so a frame never waits on a sort.
//!
//! Three order buffers circulate (front: being drawn, ready: newest finished and not yet
//! taken, back: being sorted); handing one over swaps `Vec`s under a mutex held for a few
//! pointer moves, and after warm-up nothing is allocated. Requests that arrive while a sort
//! runs replace each other: only the newest is sorted next.

use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::{Outcome, SortMode, Sorter};
use crate::cull::{CropBox, CullBounds, Frustum};

/// A camera to sort for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SortRequest {
    /// Key: distance or view depth.
    pub mode: SortMode,
    /// Camera centre, world space.
    pub eye: [f32; 3],
    /// Unit view direction (used by [`SortMode::ViewDepth`] only).
    pub forward: [f32; 3],
}

impl SortRequest {
    /// A `cameraDistance` request for `eye`.
    pub fn distance(eye: [f32; 3]) -> Self {
        SortRequest {
            mode: SortMode::Distance,
            eye,
            forward: [0.0; 3],
        }
    }

    /// A request for a [`Camera`](crate::camera::Camera).
    pub fn for_camera(camera: &crate::camera::Camera, mode: SortMode) -> Self {
        SortRequest {
            mode,
            eye: camera.eye().to_array(),
            forward: camera.world_to_camera.row(2).truncate().to_array(),
        }
    }
}

/// A finished order.
#[derive(Debug, Clone)]
pub struct SortedFrame {
    order: Vec<u32>,
    request: Option<SortRequest>,
    frustum: Option<Frustum>,
    crop: Option<CropBox>,
    generation: u64,
    outcome: Outcome,
    exact_radius: f64,
    sort_time: Duration,
}

impl SortedFrame {
    fn empty() -> Self {
        SortedFrame {
            order: Vec::new(),
            request: None,
            frustum: None,
            crop: None,
            generation: 0,
            outcome: Outcome::None,
            exact_radius: 0.0,
            sort_time: Duration::ZERO,
        }
    }

    /// How far the eye may be from the request's eye with this order still exactly the one a
    /// fresh sort would return (distance sorts with [`Reuse::MotionBound`](super::Reuse), full
    /// precision; 0 otherwise or when nothing is provably safe). For a reused order it is the
    /// sorter's safe radius minus the distance the request's eye had moved from the sorted eye.
    pub fn exact_radius(&self) -> f64 {
        self.exact_radius
    }

    /// Wall time the worker spent on this request (keys, sort and, with
    /// [`Reuse::MotionBound`](super::Reuse), the safe radius; near zero when reused).
    pub fn sort_time(&self) -> Duration {
        self.sort_time
    }

    /// Splat indices back to front.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// The request this order was sorted for.
    pub fn request(&self) -> Option<SortRequest> {
        self.request
    }

    /// The frustum the order was culled for ([`AsyncSorter::request_visible`]); `None`: every
    /// splat is in the order.
    pub fn frustum(&self) -> Option<Frustum> {
        self.frustum
    }

    /// The crop box the order was cut to ([`AsyncSorter::set_crop`]); `None`: not cropped.
    pub fn crop(&self) -> Option<CropBox> {
        self.crop
    }

    /// The generation [`AsyncSorter::request`] returned for that request.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// Whether the order was sorted or reused (see [`Sorter::last_outcome`]).
    pub fn outcome(&self) -> Outcome {
        self.outcome
    }
}

#[derive(Debug)]
struct State {
    pending: Option<(u64, SortRequest, Option<Frustum>)>,
    /// Cuts the orders of the requests posted from now on.
    crop: Option<CropBox>,
    ready: Option<SortedFrame>,
    spare: Option<SortedFrame>,
    finished: u64,
    issued: u64,
    stop: bool,
}

#[derive(Debug)]
struct Shared {
    state: Mutex<State>,
    /// Wakes the worker (new request or stop).
    wake: Condvar,
    /// Wakes [`AsyncSorter::wait_for`] (a frame finished or the worker stopped).
    done: Condvar,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        // The state stays consistent at every unlock, so a poisoned lock is still usable.
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

/// Sorts on a background thread: [`request`](Self::request) posts the newest camera,
/// [`latest`](Self::latest) returns the newest finished order. Neither waits for a sort; the
/// order buffers are triple-buffered and recycled (no allocation after warm-up).
#[derive(Debug)]
pub struct AsyncSorter {
    shared: Arc<Shared>,
    front: Option<SortedFrame>,
    worker: Option<JoinHandle<()>>,
}

/// Marks the worker stopped however it exits (also on panic), so waiters never hang.
struct StopOnExit(Arc<Shared>);
impl Drop for StopOnExit {
    fn drop(&mut self) {
        self.0.lock().stop = true;
        self.0.done.notify_all();
    }
}

impl AsyncSorter {
    /// Starts a sorter thread over `positions` with `sorter`'s precision and reuse policy.
    ///
    /// # Errors
    /// When the OS cannot start a thread.
    pub fn new(positions: Arc<[[f32; 3]]>, sorter: Sorter) -> std::io::Result<Self> {
        Self::start(positions, None, sorter)
    }

    /// [`AsyncSorter::new`] with the cloud's cull radii, so that
    /// [`AsyncSorter::request_visible`] sorts only the splats a frustum may see.
    ///
    /// # Errors
    /// When the OS cannot start a thread.
    ///
    /// # Panics
    /// If `bounds` does not have one radius per position.
    pub fn with_bounds(
        positions: Arc<[[f32; 3]]>,
        bounds: Arc<CullBounds>,
        sorter: Sorter,
    ) -> std::io::Result<Self> {
        assert_eq!(bounds.len(), positions.len(), "one cull radius per splat");
        Self::start(positions, Some(bounds), sorter)
    }

    fn start(
        positions: Arc<[[f32; 3]]>,
        bounds: Option<Arc<CullBounds>>,
        mut sorter: Sorter,
    ) -> std::io::Result<Self> {
        let shared = Arc::new(Shared {
            state: Mutex::new(State {
                pending: None,
                crop: None,
                ready: None,
                spare: None,
                finished: 0,
                issued: 0,
                stop: false,
            }),
            wake: Condvar::new(),
            done: Condvar::new(),
        });
        let sh = Arc::clone(&shared);
        let worker = std::thread::Builder::new()
            .name("splatgl-sort".into())
            .spawn(move || {
                let _stop = StopOnExit(Arc::clone(&sh));
                let mut back = SortedFrame::empty();
                loop {
                    let (generation, req, frustum, crop) = {
                        let mut st = sh.lock();
                        loop {
                            if st.stop {
                                return;
                            }
                            if let Some((g, r, f)) = st.pending.take() {
                                break (g, r, f, st.crop);
                            }
                            st = sh.wake.wait(st).unwrap_or_else(PoisonError::into_inner);
                        }
                    };
                    let started = Instant::now();
                    let culled = frustum.zip(bounds.as_deref());
                    let order = match (culled, req.mode) {
                        (Some((f, b)), _) => sorter.sort_visible(&positions, b, &f, &req),
                        (None, SortMode::Distance) => sorter.sort_by_distance(&positions, req.eye),
                        (None, SortMode::ViewDepth) => {
                            sorter.sort_by_view_depth(&positions, req.eye, req.forward)
                        }
                    };
                    back.order.clear();
                    match crop {
                        Some(c) => back
                            .order
                            .extend(order.iter().filter(|&&i| c.contains(positions[i as usize]))),
                        None => back.order.extend_from_slice(order),
                    }
                    back.request = Some(req);
                    back.frustum = culled.map(|(f, _)| f);
                    back.crop = crop;
                    back.generation = generation;
                    back.outcome = sorter.last_outcome();
                    back.exact_radius = match back.outcome {
                        Outcome::ReusedWithinBound { moved, radius } => (radius - moved).max(0.0),
                        _ => sorter.reuse_radius(),
                    };
                    back.sort_time = started.elapsed();
                    let mut st = sh.lock();
                    let unread = st.ready.replace(back);
                    back = unread
                        .or_else(|| st.spare.take())
                        .unwrap_or_else(SortedFrame::empty);
                    st.finished = generation;
                    drop(st);
                    sh.done.notify_all();
                }
            })?;
        Ok(AsyncSorter {
            shared,
            front: None,
            worker: Some(worker),
        })
    }

    /// Posts the newest camera (replacing any request not yet started) and returns its
    /// generation number (1, 2, …). Never waits for a sort.
    pub fn request(&self, request: SortRequest) -> u64 {
        self.post(request, None)
    }

    /// [`AsyncSorter::request`] of only the splats `frustum` may see
    /// ([`Sorter::sort_visible`]): the frame's order is valid for that frustum only (a view
    /// turned or moved since may show splats it left out). Without bounds
    /// ([`AsyncSorter::new`]) the frustum is ignored and every splat is sorted.
    pub fn request_visible(&self, request: SortRequest, frustum: Frustum) -> u64 {
        self.post(request, Some(frustum))
    }

    /// Cuts the orders of every request posted from now on to the splats whose mean lies
    /// inside `crop` (the viewer's crop box; `None`: no cut). Orders already posted or finished
    /// keep the crop they were posted with ([`SortedFrame::crop`]).
    pub fn set_crop(&self, crop: Option<CropBox>) {
        self.shared.lock().crop = crop;
    }

    fn post(&self, request: SortRequest, frustum: Option<Frustum>) -> u64 {
        let mut st = self.shared.lock();
        st.issued += 1;
        let generation = st.issued;
        st.pending = Some((generation, request, frustum));
        drop(st);
        self.shared.wake.notify_one();
        generation
    }

    /// The newest finished order (switching to it if one finished since the last call), or
    /// `None` before the first sort finished. Never waits for a sort.
    pub fn latest(&mut self) -> Option<&SortedFrame> {
        let mut st = self.shared.lock();
        if let Some(new) = st.ready.take()
            && let Some(old) = self.front.replace(new)
        {
            st.spare = Some(old);
        }
        drop(st);
        self.front.as_ref()
    }

    /// The order the last [`latest`](Self::latest) or [`wait_for`](Self::wait_for) returned,
    /// without switching to a newer one (so a caller can check an order and then draw that
    /// same order).
    pub fn current(&self) -> Option<&SortedFrame> {
        self.front.as_ref()
    }

    /// Blocks until the order of request `generation` (or a newer one) finished, then returns
    /// the newest order, for renders that must be deterministic. `None` if the worker stopped
    /// first (it panicked) or `generation` was never issued.
    pub fn wait_for(&mut self, generation: u64) -> Option<&SortedFrame> {
        let mut st = self.shared.lock();
        if generation > st.issued {
            return None;
        }
        while st.finished < generation && !st.stop {
            st = self
                .shared
                .done
                .wait(st)
                .unwrap_or_else(PoisonError::into_inner);
        }
        let reached = st.finished >= generation;
        drop(st);
        if reached { self.latest() } else { None }
    }
}

impl Drop for AsyncSorter {
    fn drop(&mut self) {
        self.shared.lock().stop = true;
        self.shared.wake.notify_all();
        if let Some(w) = self.worker.take() {
            // A panic in the worker was already reported on its thread.
            let _ = w.join();
        }
    }
}
