//! Minimal safe bindings to Embree 3 (tested against 3.13.5 on Debian).
//!
//! Only triangle meshes, single-level scenes and occlusion / closest-hit
//! queries are exposed. The raw declarations in [`sys`] mirror
//! `<embree3/rtcore*.h>`; their layouts are checked in the unit tests. The library is opened
//! (`dlopen`) when the first device is made, so that a program that never traces a ray neither
//! needs it installed nor pays for loading it.

use std::ffi::{CStr, CString, c_char, c_void};
use std::fmt;
use std::sync::{Arc, Mutex, PoisonError};

/// Embree's functions `fns` (their C declarations, as in `rtcore*.h`): a table of pointers
/// ([`sys`]'s `Api`) filled from the library when it is opened, and a function of each name
/// calling through it.
macro_rules! embree_api {
    ($(fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)?;)*) => {
        struct Api {
            $($name: unsafe extern "C" fn($($ty),*) $(-> $ret)?,)*
        }

        impl Api {
            /// Each function in the opened library `handle`; the name of the first missing.
            ///
            /// # Safety
            /// `handle` must be Embree 3's library, open for the rest of the program.
            unsafe fn find(handle: *mut c_void) -> Result<Api, &'static str> {
                Ok(Api {
                    $($name: {
                        let symbol = concat!(stringify!($name), "\0");
                        // SAFETY: `symbol` is NUL-terminated; `handle` is open.
                        let found = unsafe { dlsym(handle, symbol.as_ptr().cast()) };
                        if found.is_null() {
                            return Err(stringify!($name));
                        }
                        // SAFETY: Embree 3 declares the function of this name with this
                        // signature; a data pointer from `dlsym` is the function's address.
                        unsafe {
                            std::mem::transmute::<
                                *mut c_void,
                                unsafe extern "C" fn($($ty),*) $(-> $ret)?,
                            >(found)
                        }
                    },)*
                })
            }
        }

        $(
            /// Embree's function of this name.
            ///
            /// # Safety
            /// As Embree documents it; [`load`] must have succeeded.
            pub unsafe fn $name($($arg: $ty),*) $(-> $ret)? {
                // SAFETY: the caller keeps Embree's contract for the call.
                unsafe { (api().$name)($($arg),*) }
            }
        )*
    };
}

/// Raw declarations for the subset of the Embree 3 C API we use.
#[allow(non_camel_case_types, non_snake_case, dead_code)]
pub mod sys {
    use std::ffi::{c_char, c_int, c_uint, c_void};
    use std::sync::OnceLock;

    #[repr(C)]
    pub struct RTCDeviceTy {
        _opaque: [u8; 0],
    }
    #[repr(C)]
    pub struct RTCSceneTy {
        _opaque: [u8; 0],
    }
    #[repr(C)]
    pub struct RTCGeometryTy {
        _opaque: [u8; 0],
    }
    #[repr(C)]
    pub struct RTCFilterFunctionNArguments {
        _opaque: [u8; 0],
    }
    pub type RTCDevice = *mut RTCDeviceTy;
    pub type RTCScene = *mut RTCSceneTy;
    pub type RTCGeometry = *mut RTCGeometryTy;

    // C enums are plain integers here: a Rust enum would be UB for any
    // value Embree returns that we did not list.
    pub type RTCError = c_uint;
    pub const RTC_ERROR_NONE: RTCError = 0;
    pub const RTC_ERROR_UNKNOWN: RTCError = 1;
    pub const RTC_ERROR_INVALID_ARGUMENT: RTCError = 2;
    pub const RTC_ERROR_INVALID_OPERATION: RTCError = 3;
    pub const RTC_ERROR_OUT_OF_MEMORY: RTCError = 4;
    pub const RTC_ERROR_UNSUPPORTED_CPU: RTCError = 5;
    pub const RTC_ERROR_CANCELLED: RTCError = 6;

    pub type RTCSceneFlags = c_uint;
    pub const RTC_SCENE_FLAG_NONE: RTCSceneFlags = 0;
    pub const RTC_SCENE_FLAG_ROBUST: RTCSceneFlags = 1 << 2;

    pub type RTCBuildQuality = c_uint;
    pub const RTC_BUILD_QUALITY_MEDIUM: RTCBuildQuality = 1;

    pub type RTCGeometryType = c_uint;
    pub const RTC_GEOMETRY_TYPE_TRIANGLE: RTCGeometryType = 0;

    pub type RTCBufferType = c_uint;
    pub const RTC_BUFFER_TYPE_INDEX: RTCBufferType = 0;
    pub const RTC_BUFFER_TYPE_VERTEX: RTCBufferType = 1;

    pub type RTCFormat = c_uint;
    pub const RTC_FORMAT_UINT3: RTCFormat = 0x5003;
    pub const RTC_FORMAT_FLOAT3: RTCFormat = 0x9003;

    pub type RTCIntersectContextFlags = c_uint;
    pub const RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT: RTCIntersectContextFlags = 0;
    pub const RTC_INTERSECT_CONTEXT_FLAG_COHERENT: RTCIntersectContextFlags = 1;

    pub const RTC_INVALID_GEOMETRY_ID: c_uint = !0;
    /// From the installed `rtcore_config.h`; changes the layout of
    /// `RTCHit` and `RTCIntersectContext`.
    pub const RTC_MAX_INSTANCE_LEVEL_COUNT: usize = 1;

    pub type RTCErrorFunction =
        Option<unsafe extern "C" fn(user_ptr: *mut c_void, code: RTCError, msg: *const c_char)>;
    pub type RTCFilterFunctionN =
        Option<unsafe extern "C" fn(args: *const RTCFilterFunctionNArguments)>;

    /// `struct RTCIntersectContext` for `RTC_MAX_INSTANCE_LEVEL_COUNT == 1`
    /// and `RTC_MIN_WIDTH == 0` (no `instStackSize` / `minWidthDistanceFactor`).
    #[repr(C)]
    #[derive(Debug, Clone, Copy)]
    pub struct RTCIntersectContext {
        pub flags: RTCIntersectContextFlags,
        pub filter: RTCFilterFunctionN,
        pub instID: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
    }

    #[repr(C, align(16))]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct RTCRay {
        pub org_x: f32,
        pub org_y: f32,
        pub org_z: f32,
        pub tnear: f32,
        pub dir_x: f32,
        pub dir_y: f32,
        pub dir_z: f32,
        pub time: f32,
        pub tfar: f32,
        pub mask: c_uint,
        pub id: c_uint,
        pub flags: c_uint,
    }

    #[repr(C, align(16))]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct RTCHit {
        pub Ng_x: f32,
        pub Ng_y: f32,
        pub Ng_z: f32,
        pub u: f32,
        pub v: f32,
        pub primID: c_uint,
        pub geomID: c_uint,
        pub instID: [c_uint; RTC_MAX_INSTANCE_LEVEL_COUNT],
    }

    #[repr(C)]
    #[derive(Debug, Clone, Copy, Default)]
    pub struct RTCRayHit {
        pub ray: RTCRay,
        pub hit: RTCHit,
    }

    /// `struct RTCRay8` (`K = 8`, which C aligns to 32 bytes) and `struct RTCRay16` (`K = 16`):
    /// one array of `K` lanes per field. 64-byte alignment serves both.
    #[repr(C, align(64))]
    #[derive(Debug, Clone, Copy)]
    pub struct RTCRayK<const K: usize> {
        pub org_x: [f32; K],
        pub org_y: [f32; K],
        pub org_z: [f32; K],
        pub tnear: [f32; K],
        pub dir_x: [f32; K],
        pub dir_y: [f32; K],
        pub dir_z: [f32; K],
        pub time: [f32; K],
        pub tfar: [f32; K],
        pub mask: [c_uint; K],
        pub id: [c_uint; K],
        pub flags: [c_uint; K],
    }

    /// `struct RTCHit8` / `struct RTCHit16`, as [`RTCRayK`].
    #[repr(C, align(64))]
    #[derive(Debug, Clone, Copy)]
    pub struct RTCHitK<const K: usize> {
        pub Ng_x: [f32; K],
        pub Ng_y: [f32; K],
        pub Ng_z: [f32; K],
        pub u: [f32; K],
        pub v: [f32; K],
        pub primID: [c_uint; K],
        pub geomID: [c_uint; K],
        pub instID: [[c_uint; K]; RTC_MAX_INSTANCE_LEVEL_COUNT],
    }

    /// `struct RTCRayHit8` / `struct RTCRayHit16`.
    #[repr(C)]
    #[derive(Debug, Clone, Copy)]
    pub struct RTCRayHitK<const K: usize> {
        pub ray: RTCRayK<K>,
        pub hit: RTCHitK<K>,
    }

    pub type RTCRay8 = RTCRayK<8>;
    pub type RTCHit8 = RTCHitK<8>;
    pub type RTCRayHit8 = RTCRayHitK<8>;
    pub type RTCRay16 = RTCRayK<16>;
    pub type RTCHit16 = RTCHitK<16>;
    pub type RTCRayHit16 = RTCRayHitK<16>;

    pub type RTCDeviceProperty = c_uint;
    pub const RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED: RTCDeviceProperty = 34;

    // Embree is opened when the first device is made, not when the program starts: the
    // commands that never trace a ray (bsp, vis, info) do not load it and its thread pool, and
    // start in a couple of milliseconds less.
    embree_api! {
        fn rtcNewDevice(config: *const c_char) -> RTCDevice;
        fn rtcReleaseDevice(device: RTCDevice);
        fn rtcGetDeviceError(device: RTCDevice) -> RTCError;
        fn rtcGetDeviceProperty(device: RTCDevice, prop: RTCDeviceProperty) -> isize;
        fn rtcSetDeviceErrorFunction(
            device: RTCDevice,
            error: RTCErrorFunction,
            user_ptr: *mut c_void,
        );

        fn rtcNewScene(device: RTCDevice) -> RTCScene;
        fn rtcReleaseScene(scene: RTCScene);
        fn rtcSetSceneFlags(scene: RTCScene, flags: RTCSceneFlags);
        fn rtcSetSceneBuildQuality(scene: RTCScene, quality: RTCBuildQuality);
        fn rtcAttachGeometry(scene: RTCScene, geometry: RTCGeometry) -> c_uint;
        fn rtcCommitScene(scene: RTCScene);

        fn rtcNewGeometry(device: RTCDevice, ty: RTCGeometryType) -> RTCGeometry;
        fn rtcSetNewGeometryBuffer(
            geometry: RTCGeometry,
            ty: RTCBufferType,
            slot: c_uint,
            format: RTCFormat,
            byte_stride: usize,
            item_count: usize,
        ) -> *mut c_void;
        fn rtcCommitGeometry(geometry: RTCGeometry);
        fn rtcReleaseGeometry(geometry: RTCGeometry);

        fn rtcIntersect1(
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit,
        );
        fn rtcOccluded1(scene: RTCScene, context: *mut RTCIntersectContext, ray: *mut RTCRay);
        fn rtcOccluded16(
            valid: *const c_int,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            ray: *mut RTCRay16,
        );
        fn rtcIntersect16(
            valid: *const c_int,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit16,
        );
        fn rtcOccluded8(
            valid: *const c_int,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            ray: *mut RTCRay8,
        );
        fn rtcIntersect8(
            valid: *const c_int,
            scene: RTCScene,
            context: *mut RTCIntersectContext,
            rayhit: *mut RTCRayHit8,
        );
    }

    /// The file Debian's `libembree3-3` installs (`libembree-dev` depends on it).
    const LIBRARY: &std::ffi::CStr = c"libembree3.so.3";

    #[link(name = "dl")]
    unsafe extern "C" {
        fn dlopen(filename: *const c_char, flags: c_int) -> *mut c_void;
        fn dlsym(handle: *mut c_void, symbol: *const c_char) -> *mut c_void;
        fn dlerror() -> *mut c_char;
    }

    /// `dlopen`'s flags (`<dlfcn.h>`): every symbol resolved at once, none made global.
    const RTLD_NOW: c_int = 2;

    static API: OnceLock<Result<Api, String>> = OnceLock::new();

    /// Opens Embree's library and finds its entry points, once: why it cannot be used, if it
    /// cannot. Every call below needs this to have succeeded; a device is made only after it.
    pub fn load() -> Result<(), String> {
        API.get_or_init(open)
            .as_ref()
            .map(|_| ())
            .map_err(Clone::clone)
    }

    fn api() -> &'static Api {
        match API.get() {
            Some(Ok(api)) => api,
            // Every Embree object comes from a device, and a device is made after `load`.
            _ => panic!("Embree called before it was loaded"),
        }
    }

    fn open() -> Result<Api, String> {
        open_library(LIBRARY)
    }

    /// The library `library` opened as Embree's.
    fn open_library(library: &std::ffi::CStr) -> Result<Api, String> {
        let name = library.to_string_lossy();
        // SAFETY: `library` is NUL-terminated.
        let handle = unsafe { dlopen(library.as_ptr(), RTLD_NOW) };
        if handle.is_null() {
            // SAFETY: `dlerror` returns NULL or the calling thread's message, NUL-terminated.
            let why = unsafe {
                let message = dlerror();
                if message.is_null() {
                    String::from("unknown reason")
                } else {
                    std::ffi::CStr::from_ptr(message)
                        .to_string_lossy()
                        .into_owned()
                }
            };
            return Err(format!("{name} could not be loaded ({why})"));
        }
        // SAFETY: `handle` is the library just opened, never closed.
        unsafe { Api::find(handle) }.map_err(|missing| format!("{name} has no {missing}"))
    }

    #[cfg(test)]
    mod tests {
        use super::*;

        #[test]
        fn a_library_that_is_not_there_or_not_embree_says_so() {
            let missing = open_library(c"libslipgate-no-such-embree.so.0").err();
            assert!(missing.is_some_and(|why| {
                why.starts_with("libslipgate-no-such-embree.so.0 could not be loaded")
            }),);
            // The C library is there, and has none of Embree's functions.
            let libc = open_library(c"libc.so.6").err();
            assert_eq!(libc.as_deref(), Some("libc.so.6 has no rtcNewDevice"));
            let shown = crate::embree::EmbreeError::Unavailable("x could not be loaded".into());
            assert!(
                shown.to_string().contains("apt install libembree3-3"),
                "{shown}"
            );
        }
    }
}

/// An Embree API failure or input rejected before reaching Embree.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum EmbreeError {
    /// Embree reported an error code during `op`.
    Api {
        op: &'static str,
        /// An `RTC_ERROR_*` value.
        code: u32,
        /// Best-effort text from Embree's error callback (the callback is
        /// per device, so under concurrent failures it may be another thread's).
        message: Option<String>,
    },
    /// Input rejected before reaching Embree (e.g. a vertex index out of range).
    InvalidInput(String),
    /// Embree's library could not be opened, or lacks a function light calls.
    Unavailable(String),
}

fn error_code_name(code: u32) -> &'static str {
    match code {
        sys::RTC_ERROR_NONE => "no error",
        sys::RTC_ERROR_UNKNOWN => "unknown error",
        sys::RTC_ERROR_INVALID_ARGUMENT => "invalid argument",
        sys::RTC_ERROR_INVALID_OPERATION => "invalid operation",
        sys::RTC_ERROR_OUT_OF_MEMORY => "out of memory",
        sys::RTC_ERROR_UNSUPPORTED_CPU => "unsupported CPU",
        sys::RTC_ERROR_CANCELLED => "cancelled",
        _ => "unrecognised error code",
    }
}

impl fmt::Display for EmbreeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Api { op, code, message } => {
                write!(f, "embree {op} failed: {} ({code})", error_code_name(*code))?;
                match message {
                    Some(m) => write!(f, ": {m}"),
                    None => Ok(()),
                }
            }
            Self::InvalidInput(why) => write!(f, "invalid input: {why}"),
            Self::Unavailable(why) => write!(
                f,
                "Embree 3 is needed to trace light and {why}; on Debian, `apt install libembree3-3`"
            ),
        }
    }
}

impl std::error::Error for EmbreeError {}

/// Owns the device handle plus the slot the error callback writes into.
struct DeviceInner {
    raw: sys::RTCDevice,
    /// Whether the kernels Embree chose trace 16-wide packets natively (AVX-512); without
    /// them, its 16-wide calls go through its ray-stream filter, which regathers every packet.
    native16: bool,
    // Boxed so the address handed to Embree as `userPtr` never moves.
    last_message: Box<Mutex<Option<String>>>,
}

// SAFETY: Embree devices may be used from any thread; every Embree error
// code is per thread, and our message slot is behind a Mutex.
unsafe impl Send for DeviceInner {}
// SAFETY: as above; we only call thread-safe Embree entry points via `&self`.
unsafe impl Sync for DeviceInner {}

impl DeviceInner {
    /// Turns the calling thread's pending Embree error (if any) into `Err`.
    fn check(&self, op: &'static str) -> Result<(), EmbreeError> {
        // SAFETY: `raw` is a live device for as long as `self` exists.
        let code = unsafe { sys::rtcGetDeviceError(self.raw) };
        if code == sys::RTC_ERROR_NONE {
            return Ok(());
        }
        let message = self
            .last_message
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .take();
        Err(EmbreeError::Api { op, code, message })
    }
}

impl Drop for DeviceInner {
    fn drop(&mut self) {
        // SAFETY: we hold one reference; scenes/geometries hold their own, and
        // every Rust scene keeps this `DeviceInner` (and thus the callback's
        // user pointer) alive through an `Arc`.
        unsafe { sys::rtcReleaseDevice(self.raw) };
    }
}

unsafe extern "C" fn record_error(user_ptr: *mut c_void, _code: sys::RTCError, msg: *const c_char) {
    if user_ptr.is_null() || msg.is_null() {
        return;
    }
    // SAFETY: `user_ptr` is the boxed Mutex registered in `Device::new`, which
    // outlives the device; `msg` is a NUL-terminated string valid for this call.
    let (slot, text) = unsafe {
        (
            &*user_ptr.cast::<Mutex<Option<String>>>(),
            CStr::from_ptr(msg).to_string_lossy().into_owned(),
        )
    };
    // Must not panic across the FFI boundary: tolerate poisoning.
    *slot.lock().unwrap_or_else(PoisonError::into_inner) = Some(text);
}

/// Environment variable whose value is appended to the config string of the
/// devices `Device::new` creates: Embree 3 options such as `isa=avx2`,
/// `isa=sse4.2` (which vector kernels trace the rays) or `verbose=1`.
pub const CONFIG_ENV: &str = "SLIPGATE_EMBREE_CONFIG";

/// The config string for a device with `threads` builder threads, followed by
/// the options `extra`.
fn device_config(threads: usize, extra: &str) -> String {
    let extra = extra.trim();
    if extra.is_empty() {
        format!("threads={threads},set_affinity=0")
    } else {
        format!("threads={threads},set_affinity=0,{extra}")
    }
}

/// Opens Embree's library (and TBB's), which the first device otherwise opens: milliseconds of
/// dynamic loading that may run beside other work.
///
/// # Errors
/// Why the library cannot be opened.
pub fn open_library() -> Result<(), EmbreeError> {
    sys::load().map_err(EmbreeError::Unavailable)
}

/// An Embree device; cheap to clone (reference counted).
#[derive(Clone)]
pub struct Device {
    inner: Arc<DeviceInner>,
}

impl fmt::Debug for Device {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Device")
            .field("raw", &self.inner.raw)
            .finish()
    }
}

impl Device {
    /// Creates a device whose BVH builder uses at most `threads` threads
    /// (0 = all hardware threads), with the options in the environment
    /// variable [`CONFIG_ENV`] if it is set (see [`Device::with_options`]).
    ///
    /// # Errors
    /// As [`Device::with_options`]; also when [`CONFIG_ENV`] is not Unicode.
    pub fn new(threads: usize) -> Result<Self, EmbreeError> {
        let extra = match std::env::var(CONFIG_ENV) {
            Ok(extra) => extra,
            Err(std::env::VarError::NotPresent) => String::new(),
            Err(std::env::VarError::NotUnicode(_)) => {
                return Err(EmbreeError::InvalidInput(format!(
                    "{CONFIG_ENV} is not valid Unicode"
                )));
            }
        };
        Self::with_options(threads, &extra)
    }

    /// Creates a device whose BVH builder uses at most `threads` threads
    /// (0 = all hardware threads), followed by the Embree options `extra`
    /// (e.g. `isa=sse4.2`, which runs the SSE kernels on any x86-64 CPU).
    /// The count is capped at the machine's parallelism so Embree's TBB pool
    /// does not oversubscribe alongside rayon.
    ///
    /// # Errors
    /// Fails if Embree cannot create a device (e.g. unsupported CPU, or an
    /// `isa` in `extra` that this CPU lacks).
    pub fn with_options(threads: usize, extra: &str) -> Result<Self, EmbreeError> {
        open_library()?;
        let hw = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
        let threads = if threads == 0 { hw } else { threads.min(hw) };
        let config = CString::new(device_config(threads, extra))
            .map_err(|_| EmbreeError::InvalidInput("device config contained NUL".into()))?;
        // SAFETY: `config` is a valid NUL-terminated string for the call.
        let raw = unsafe { sys::rtcNewDevice(config.as_ptr()) };
        if raw.is_null() {
            // SAFETY: passing NULL is the documented way to get the
            // error of a failed device construction.
            let code = unsafe { sys::rtcGetDeviceError(std::ptr::null_mut()) };
            return Err(EmbreeError::Api {
                op: "rtcNewDevice",
                code,
                message: None,
            });
        }
        // SAFETY: `raw` is a live device.
        let native16 = unsafe {
            sys::rtcGetDeviceProperty(raw, sys::RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)
        } != 0;
        let inner = DeviceInner {
            raw,
            native16,
            last_message: Box::new(Mutex::new(None)),
        };
        let user_ptr = std::ptr::from_ref::<Mutex<Option<String>>>(&inner.last_message).cast_mut();
        // SAFETY: `raw` is live; `user_ptr` points into a Box owned by `inner`
        // that is freed only after `rtcReleaseDevice` in `DeviceInner::drop`.
        unsafe { sys::rtcSetDeviceErrorFunction(raw, Some(record_error), user_ptr.cast()) };
        inner.check("rtcSetDeviceErrorFunction")?;
        Ok(Self {
            inner: Arc::new(inner),
        })
    }
}

/// Owns one scene reference and keeps the device alive.
struct SceneHandle {
    raw: sys::RTCScene,
    device: Arc<DeviceInner>,
}

impl Drop for SceneHandle {
    fn drop(&mut self) {
        // SAFETY: `raw` is a live scene we hold one reference to.
        unsafe { sys::rtcReleaseScene(self.raw) };
    }
}

/// Releases a geometry handle on every exit path of `add_triangle_mesh`.
struct GeometryGuard(sys::RTCGeometry);

impl Drop for GeometryGuard {
    fn drop(&mut self) {
        // SAFETY: the guard owns exactly one reference to a live geometry.
        unsafe { sys::rtcReleaseGeometry(self.0) };
    }
}

/// Collects geometry for a [`Scene`]; call [`SceneBuilder::commit`] to build.
pub struct SceneBuilder {
    handle: SceneHandle,
}

// SAFETY: Embree objects are not tied to the creating thread; `&mut self`
// methods keep modifications sequential as Embree requires.
unsafe impl Send for SceneBuilder {}

impl SceneBuilder {
    /// Starts an empty scene on `device`.
    ///
    /// # Errors
    /// Returns the Embree error if the scene cannot be created.
    pub fn new(device: &Device) -> Result<Self, EmbreeError> {
        // SAFETY: the device is live for the duration of the call.
        let raw = unsafe { sys::rtcNewScene(device.inner.raw) };
        if raw.is_null() {
            device.inner.check("rtcNewScene")?;
            return Err(EmbreeError::Api {
                op: "rtcNewScene",
                code: sys::RTC_ERROR_UNKNOWN,
                message: None,
            });
        }
        let handle = SceneHandle {
            raw,
            device: Arc::clone(&device.inner),
        };
        Ok(Self { handle })
    }

    /// Adds a triangle mesh and returns the geometry id Embree reports for its hits. Ids are
    /// assigned sequentially from 0.
    ///
    /// # Errors
    /// [`EmbreeError::InvalidInput`] for an out-of-range vertex index, or the
    /// Embree error if creating the geometry fails.
    pub fn add_triangle_mesh(
        &mut self,
        vertices: &[[f32; 3]],
        triangles: &[[u32; 3]],
    ) -> Result<u32, EmbreeError> {
        // Embree does not bounds-check indices; a bad one would read out of
        // bounds during the build or traversal.
        if let Some(bad) = triangles
            .iter()
            .flatten()
            .find(|&&i| i as usize >= vertices.len())
        {
            return Err(EmbreeError::InvalidInput(format!(
                "vertex index {bad} out of range ({} vertices)",
                vertices.len()
            )));
        }
        // Primitive ids are 32-bit.
        if u32::try_from(triangles.len()).is_err() {
            return Err(EmbreeError::InvalidInput(
                "more than u32::MAX triangles".into(),
            ));
        }
        let dev = &self.handle.device;
        // SAFETY: the device is live.
        let raw = unsafe { sys::rtcNewGeometry(dev.raw, sys::RTC_GEOMETRY_TYPE_TRIANGLE) };
        if raw.is_null() {
            dev.check("rtcNewGeometry")?;
            return Err(EmbreeError::Api {
                op: "rtcNewGeometry",
                code: sys::RTC_ERROR_UNKNOWN,
                message: None,
            });
        }
        let geom = GeometryGuard(raw);
        set_buffer(
            dev,
            geom.0,
            sys::RTC_BUFFER_TYPE_VERTEX,
            sys::RTC_FORMAT_FLOAT3,
            vertices,
        )?;
        set_buffer(
            dev,
            geom.0,
            sys::RTC_BUFFER_TYPE_INDEX,
            sys::RTC_FORMAT_UINT3,
            triangles,
        )?;
        // SAFETY: `geom.0` is live and both buffers are set.
        unsafe { sys::rtcCommitGeometry(geom.0) };
        dev.check("rtcCommitGeometry")?;
        // SAFETY: scene and geometry are live and belong to the same device.
        let id = unsafe { sys::rtcAttachGeometry(self.handle.raw, geom.0) };
        dev.check("rtcAttachGeometry")?;
        // `geom` drops here: the scene now holds its own reference.
        Ok(id)
    }

    /// Builds the BVH (build quality MEDIUM: the HIGH build costs more than its faster
    /// traversal saves on Quake maps), robust: without `RTC_SCENE_FLAG_ROBUST` Embree's
    /// kernels let a ray through the crack between two triangles that share an edge (a sun ray
    /// reached the floor through a sky brush's seam), as ericw-tools found. The result is
    /// immutable.
    ///
    /// # Errors
    /// Returns the Embree error if the build fails (e.g. out of memory).
    pub fn commit(self) -> Result<Scene, EmbreeError> {
        self.commit_with(sys::RTC_SCENE_FLAG_ROBUST)
    }

    /// [`SceneBuilder::commit`] without the robust mode: rays are traced faster, and one that
    /// meets the edge two triangles share may pass between them.
    ///
    /// # Errors
    /// Returns the Embree error if the build fails (e.g. out of memory).
    pub fn commit_unsealed(self) -> Result<Scene, EmbreeError> {
        self.commit_with(sys::RTC_SCENE_FLAG_NONE)
    }

    fn commit_with(self, flags: sys::RTCSceneFlags) -> Result<Scene, EmbreeError> {
        let h = &self.handle;
        // SAFETY: the scene is live and not being queried or modified elsewhere
        // (we own the builder by value).
        unsafe {
            sys::rtcSetSceneFlags(h.raw, flags);
            sys::rtcSetSceneBuildQuality(h.raw, sys::RTC_BUILD_QUALITY_MEDIUM);
            sys::rtcCommitScene(h.raw);
        }
        h.device.check("rtcCommitScene")?;
        Ok(Scene {
            handle: self.handle,
        })
    }
}

/// Copies `data` into a new Embree-owned geometry buffer (Embree pads
/// vertex buffers for its 16-byte SSE loads itself).
fn set_buffer<T: Copy>(
    dev: &DeviceInner,
    geom: sys::RTCGeometry,
    ty: sys::RTCBufferType,
    format: sys::RTCFormat,
    data: &[T],
) -> Result<(), EmbreeError> {
    // SAFETY: `geom` is live; stride/count describe `data` exactly.
    let dst =
        unsafe { sys::rtcSetNewGeometryBuffer(geom, ty, 0, format, size_of::<T>(), data.len()) };
    dev.check("rtcSetNewGeometryBuffer")?;
    if dst.is_null() {
        return if data.is_empty() {
            Ok(())
        } else {
            Err(EmbreeError::Api {
                op: "rtcSetNewGeometryBuffer",
                code: sys::RTC_ERROR_OUT_OF_MEMORY,
                message: None,
            })
        };
    }
    // SAFETY: Embree allocated at least `len * size_of::<T>()` bytes at `dst`;
    // the regions cannot overlap; copying bytes needs no alignment.
    unsafe {
        std::ptr::copy_nonoverlapping(
            data.as_ptr().cast::<u8>(),
            dst.cast::<u8>(),
            size_of_val(data),
        );
    }
    Ok(())
}

/// A committed, immutable scene. Queries take `&self` and may run from
/// many threads at once.
pub struct Scene {
    handle: SceneHandle,
}

// SAFETY: after commit Embree allows concurrent queries on a scene from any
// thread, and `Scene` exposes no way to modify it.
unsafe impl Send for Scene {}
// SAFETY: as above.
unsafe impl Sync for Scene {}

/// Closest-hit result of [`Scene::intersect`] (the single-ray queries are the tests' oracle
/// for the packets).
#[cfg(test)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit (distance if `dir` is unit length).
    pub t: f32,
    pub geom_id: u32,
    /// Triangle index within the geometry.
    pub prim_id: u32,
    /// Barycentrics: `p = (1-u-v)*p0 + u*p1 + v*p2`.
    pub u: f32,
    pub v: f32,
    /// Unnormalised geometric normal, `(p1-p0) x (p2-p0)`.
    pub ng: [f32; 3],
}

/// Embree requires `0 <= tnear <= tfar` and finite origin/direction;
/// anything else is treated as an empty segment that hits nothing.
/// Embree's `FLT_LARGE`: a ray whose origin or direction has a component larger than this fails
/// its traversal's validity assertion (an abort, not an error), though it is finite.
const LARGEST_RAY_COMPONENT: f32 = 1.844e18;

fn ray_ok(org: [f32; 3], dir: [f32; 3], tnear: f32, tfar: f32) -> bool {
    org.iter()
        .chain(&dir)
        .all(|c| c.abs() <= LARGEST_RAY_COMPONENT)
        && tnear >= 0.0
        && tnear <= tfar
}

fn make_ray(org: [f32; 3], dir: [f32; 3], tnear: f32, tfar: f32) -> sys::RTCRay {
    sys::RTCRay {
        org_x: org[0],
        org_y: org[1],
        org_z: org[2],
        tnear,
        dir_x: dir[0],
        dir_y: dir[1],
        dir_z: dir[2],
        time: 0.0,
        tfar,
        // All bits set so geometry masks (if compiled in) never hide anything.
        mask: !0,
        id: 0,
        flags: 0,
    }
}

/// Equivalent of the header-inline `rtcInitIntersectContext`.
fn context(coherent: bool) -> sys::RTCIntersectContext {
    sys::RTCIntersectContext {
        flags: if coherent {
            sys::RTC_INTERSECT_CONTEXT_FLAG_COHERENT
        } else {
            sys::RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT
        },
        filter: None,
        instID: [sys::RTC_INVALID_GEOMETRY_ID; sys::RTC_MAX_INSTANCE_LEVEL_COUNT],
    }
}

impl Scene {
    /// True if anything lies on the segment `org + t*dir`, `t` in `[tnear, tfar]`.
    #[cfg(test)]
    #[must_use]
    pub fn occluded(&self, org: [f32; 3], dir: [f32; 3], tnear: f32, tfar: f32) -> bool {
        if !ray_ok(org, dir, tnear, tfar) {
            return false;
        }
        let mut ray = make_ray(org, dir, tnear, tfar);
        let mut ctx = context(false);
        // SAFETY: committed live scene; `ray` is 16-byte aligned by its type;
        // both pointers are valid for the call.
        unsafe { sys::rtcOccluded1(self.handle.raw, &raw mut ctx, &raw mut ray) };
        // Embree marks a hit by setting tfar to -inf.
        ray.tfar == f32::NEG_INFINITY
    }

    /// Closest hit on the segment, if any.
    #[cfg(test)]
    #[must_use]
    pub fn intersect(&self, org: [f32; 3], dir: [f32; 3], tnear: f32, tfar: f32) -> Option<Hit> {
        if !ray_ok(org, dir, tnear, tfar) {
            return None;
        }
        let mut rh = sys::RTCRayHit {
            ray: make_ray(org, dir, tnear, tfar),
            hit: sys::RTCHit {
                geomID: sys::RTC_INVALID_GEOMETRY_ID,
                instID: [sys::RTC_INVALID_GEOMETRY_ID; sys::RTC_MAX_INSTANCE_LEVEL_COUNT],
                ..Default::default()
            },
        };
        let mut ctx = context(false);
        // SAFETY: committed live scene; `rh` is 16-byte aligned and initialised
        // as `rtcIntersect1` requires (geomID = invalid).
        unsafe { sys::rtcIntersect1(self.handle.raw, &raw mut ctx, &raw mut rh) };
        (rh.hit.geomID != sys::RTC_INVALID_GEOMETRY_ID).then_some(Hit {
            t: rh.ray.tfar,
            geom_id: rh.hit.geomID,
            prim_id: rh.hit.primID,
            u: rh.hit.u,
            v: rh.hit.v,
            ng: [rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z],
        })
    }

    /// Occlusion test for the active lanes of `packet`; bit `i` of the result
    /// is set if lane `i` is blocked. Embree overwrites `tfar` of blocked
    /// lanes, so call [`RayPacket16::set`] again before reusing a lane.
    /// `coherent` hints that the rays share origin/direction roughly.
    pub fn occluded16(&self, packet: &mut RayPacket16, coherent: bool) -> u16 {
        if packet.active_mask() == 0 {
            return 0;
        }
        let mut ctx = context(coherent);
        if self.handle.device.native16 {
            // SAFETY: committed live scene; the valid mask and ray packet are both
            // 64-byte aligned by their types and fully initialised.
            unsafe {
                sys::rtcOccluded16(
                    packet.valid.0.as_ptr(),
                    self.handle.raw,
                    &raw mut ctx,
                    &raw mut packet.rayhit.ray,
                );
            }
        } else {
            packet.rays_by_halves(|valid, ray| {
                // SAFETY: as above, for a packet of 8 (aligned to 64 bytes, more than the 32
                // Embree asks of one).
                unsafe { sys::rtcOccluded8(valid, self.handle.raw, &raw mut ctx, ray) };
            });
        }
        (0..16)
            .filter(|&i| packet.valid.0[i] != 0 && packet.rayhit.ray.tfar[i] == f32::NEG_INFINITY)
            .fold(0, |m, i| m | (1 << i))
    }

    /// Closest hit for the active lanes of `packet`: the geometry id each lane
    /// hit first, or [`sys::RTC_INVALID_GEOMETRY_ID`] for a miss or an
    /// inactive lane. Embree shortens `tfar` of lanes that hit, so call
    /// [`RayPacket16::set`] again before reusing a lane.
    pub fn first_hit_geom16(&self, packet: &mut RayPacket16, coherent: bool) -> [u32; 16] {
        self.first_hits16(packet, coherent).map(|(geom, _)| geom)
    }

    /// As [`Scene::first_hit_geom16`], with the primitive (triangle) id of each hit.
    pub fn first_hits16(&self, packet: &mut RayPacket16, coherent: bool) -> [(u32, u32); 16] {
        let mut ids = [(sys::RTC_INVALID_GEOMETRY_ID, 0); 16];
        if packet.active_mask() == 0 {
            return ids;
        }
        // The packet holds the hit records beside its rays, so Embree answers in place instead
        // of the rays being copied out and back for every dirt packet.
        let hit = &mut packet.rayhit.hit;
        hit.geomID = [sys::RTC_INVALID_GEOMETRY_ID; 16];
        hit.instID = [[sys::RTC_INVALID_GEOMETRY_ID; 16]; sys::RTC_MAX_INSTANCE_LEVEL_COUNT];
        let mut ctx = context(coherent);
        if self.handle.device.native16 {
            // SAFETY: committed live scene; the valid mask and ray-hit packet are both 64-byte
            // aligned by their types and fully initialised (geomID invalid).
            unsafe {
                sys::rtcIntersect16(
                    packet.valid.0.as_ptr(),
                    self.handle.raw,
                    &raw mut ctx,
                    &raw mut packet.rayhit,
                );
            }
        } else {
            packet.by_halves(|valid, rayhit| {
                // SAFETY: as above, for a packet of 8.
                unsafe { sys::rtcIntersect8(valid, self.handle.raw, &raw mut ctx, rayhit) };
            });
        }
        let hit = &packet.rayhit.hit;
        for (i, id) in ids.iter_mut().enumerate() {
            if packet.valid.0[i] != 0 {
                *id = (hit.geomID[i], hit.primID[i]);
            }
        }
        ids
    }
}

#[repr(C, align(64))]
#[derive(Debug, Clone, Copy)]
struct ValidMask([i32; 16]);

/// Along one axis, where each lane's segment starts and ends, lowest first; `finite` (all
/// bits set or none) cleared for lanes where either end is not finite. Written lane by lane
/// without branches, so it runs in vectors.
#[inline(always)]
fn axis_extent(
    org: &[f32; 16],
    dir: &[f32; 16],
    (tnear, tfar): (&[f32; 16], &[f32; 16]),
    lows: &mut [f32; 16],
    highs: &mut [f32; 16],
    finite: &mut [u32; 16],
) {
    for lane in 0..16 {
        let a = org[lane] + dir[lane] * tnear[lane];
        let b = org[lane] + dir[lane] * tfar[lane];
        finite[lane] &= if a.is_finite() & b.is_finite() {
            u32::MAX
        } else {
            0
        };
        lows[lane] = if a < b { a } else { b };
        highs[lane] = if a < b { b } else { a };
    }
}

/// The boxes around a [`RayPacket16`]'s segments, per axis and lane
/// ([`RayPacket16::segment_boxes`]).
#[derive(Debug, Clone, Copy)]
pub struct SegmentBoxes16 {
    pub mins: [[f32; 16]; 3],
    pub maxs: [[f32; 16]; 3],
    /// Active lanes whose segment's ends are not finite (their boxes are empty).
    pub unbounded: u16,
}

impl SegmentBoxes16 {
    /// Bit `i` set if lane `i`'s box meets the box `mins..maxs` (touching counts).
    #[must_use]
    #[inline(always)]
    pub fn meeting(&self, mins: [f32; 3], maxs: [f32; 3]) -> u16 {
        let mut meets = [true; 16];
        for axis in 0..3 {
            for (lane, m) in meets.iter_mut().enumerate() {
                *m &= (self.mins[axis][lane] <= maxs[axis]) & (mins[axis] <= self.maxs[axis][lane]);
            }
        }
        meets
            .iter()
            .enumerate()
            .fold(0, |mask, (lane, &m)| mask | (u16::from(m) << lane))
    }

    /// The box around every lane's box: `(mins, maxs)`, empty (mins above maxs) when all are.
    #[must_use]
    #[inline(always)]
    pub fn union(&self) -> ([f32; 3], [f32; 3]) {
        // Plain comparisons: no lane holds a NaN.
        let least = |lanes: &[f32; 16]| {
            lanes
                .iter()
                .fold(f32::INFINITY, |m, &v| if v < m { v } else { m })
        };
        let most = |lanes: &[f32; 16]| {
            lanes
                .iter()
                .fold(f32::NEG_INFINITY, |m, &v| if v > m { v } else { m })
        };
        (
            std::array::from_fn(|axis| least(&self.mins[axis])),
            std::array::from_fn(|axis| most(&self.maxs[axis])),
        )
    }
}

/// Up to 16 rays for [`Scene::occluded16`], in Embree's structure-of-arrays layout.
#[derive(Debug, Clone, Copy)]
pub struct RayPacket16 {
    // Embree wants -1 for an active lane and 0 for an inactive one.
    valid: ValidMask,
    /// The rays, and the hit records [`Scene::first_hits16`] fills (unused by occlusion tests).
    rayhit: sys::RTCRayHit16,
}

impl Default for RayPacket16 {
    fn default() -> Self {
        Self::new()
    }
}

impl RayPacket16 {
    /// A packet with every lane inactive.
    #[must_use]
    pub fn new() -> Self {
        let ray = make_ray([0.0; 3], [0.0, 0.0, 1.0], 0.0, 0.0);
        Self {
            valid: ValidMask([0; 16]),
            rayhit: sys::RTCRayHit16 {
                ray: sys::RTCRay16 {
                    org_x: [0.0; 16],
                    org_y: [0.0; 16],
                    org_z: [0.0; 16],
                    tnear: [0.0; 16],
                    dir_x: [0.0; 16],
                    dir_y: [0.0; 16],
                    dir_z: [ray.dir_z; 16],
                    time: [0.0; 16],
                    tfar: [0.0; 16],
                    mask: [ray.mask; 16],
                    id: [0; 16],
                    flags: [0; 16],
                },
                hit: sys::RTCHit16 {
                    Ng_x: [0.0; 16],
                    Ng_y: [0.0; 16],
                    Ng_z: [0.0; 16],
                    u: [0.0; 16],
                    v: [0.0; 16],
                    primID: [0; 16],
                    geomID: [sys::RTC_INVALID_GEOMETRY_ID; 16],
                    instID: [[sys::RTC_INVALID_GEOMETRY_ID; 16]; sys::RTC_MAX_INSTANCE_LEVEL_COUNT],
                },
            },
        }
    }

    /// Loads a ray into `lane` and activates it (an invalid segment, see
    /// [`Scene::occluded`], leaves the lane inactive). Panics if `lane >= 16`.
    pub fn set(&mut self, lane: usize, org: [f32; 3], dir: [f32; 3], tnear: f32, tfar: f32) {
        let ok = ray_ok(org, dir, tnear, tfar);
        // Embree checks the rays of inactive lanes too (its 16-wide calls on 8-wide kernels
        // abort on one past its largest coordinate), so a refused ray is not left in the packet.
        let (org, dir, tnear, tfar) = if ok {
            (org, dir, tnear, tfar)
        } else {
            ([0.0; 3], [0.0, 0.0, 1.0], 0.0, -1.0)
        };
        let r = &mut self.rayhit.ray;
        [r.org_x[lane], r.org_y[lane], r.org_z[lane]] = org;
        [r.dir_x[lane], r.dir_y[lane], r.dir_z[lane]] = dir;
        r.tnear[lane] = tnear;
        r.tfar[lane] = tfar;
        self.valid.0[lane] = if ok { -1 } else { 0 };
    }

    /// The ray in `lane`: origin, direction, near and far ends; `None` for an inactive lane.
    #[must_use]
    pub fn segment(&self, lane: usize) -> Option<([f32; 3], [f32; 3], f32, f32)> {
        let r = &self.rayhit.ray;
        (self.valid.0[lane] != 0).then(|| {
            (
                [r.org_x[lane], r.org_y[lane], r.org_z[lane]],
                [r.dir_x[lane], r.dir_y[lane], r.dir_z[lane]],
                r.tnear[lane],
                r.tfar[lane],
            )
        })
    }

    /// The box around each active lane's segment (from `tnear` to `tfar`), lanes side by side;
    /// inactive lanes, and lanes whose ends do not compute (an infinite `tfar`), get an empty
    /// box, the latter their bit in [`SegmentBoxes16::unbounded`].
    #[must_use]
    #[inline(always)]
    pub fn segment_boxes(&self) -> SegmentBoxes16 {
        let r = &self.rayhit.ray;
        // Lanes whose box is kept (all bits set): active, with finite ends.
        let mut boxed = self.valid.0.map(|v| if v != 0 { u32::MAX } else { 0 });
        let mut boxes = SegmentBoxes16 {
            mins: [[0.0; 16]; 3],
            maxs: [[0.0; 16]; 3],
            unbounded: 0,
        };
        for (axis, (org, dir)) in [
            (&r.org_x, &r.dir_x),
            (&r.org_y, &r.dir_y),
            (&r.org_z, &r.dir_z),
        ]
        .into_iter()
        .enumerate()
        {
            axis_extent(
                org,
                dir,
                (&r.tnear, &r.tfar),
                &mut boxes.mins[axis],
                &mut boxes.maxs[axis],
                &mut boxed,
            );
        }
        // The other lanes' boxes emptied by masks, lane by lane, so this too runs in vectors.
        let pick = |kept: u32, v: f32, empty: f32| {
            f32::from_bits((v.to_bits() & kept) | (empty.to_bits() & !kept))
        };
        for axis in 0..3 {
            for (lane, &kept) in boxed.iter().enumerate() {
                let (lo, hi) = (boxes.mins[axis][lane], boxes.maxs[axis][lane]);
                boxes.mins[axis][lane] = pick(kept, lo, f32::INFINITY);
                boxes.maxs[axis][lane] = pick(kept, hi, f32::NEG_INFINITY);
            }
        }
        boxes.unbounded = (0..16).fold(0, |m, lane| {
            m | u16::from(self.valid.0[lane] != 0 && boxed[lane] == 0) << lane
        });
        boxes
    }

    /// The far end of `lane`'s segment: after [`Scene::first_hit_geom16`],
    /// the distance of the lane's hit (if it hit).
    #[must_use]
    pub fn tfar(&self, lane: usize) -> f32 {
        self.rayhit.ray.tfar[lane]
    }

    /// Keeps only the lanes in `lanes` active and ends each at `tfar(lane) * scale`.
    pub fn keep_shortened(&mut self, lanes: u16, scale: f32) {
        for i in 0..16 {
            if lanes & (1 << i) == 0 {
                self.valid.0[i] = 0;
            } else {
                self.rayhit.ray.tfar[i] *= scale;
            }
        }
    }

    /// Deactivates every lane.
    pub fn clear(&mut self) {
        self.valid.0 = [0; 16];
    }

    /// Bit `i` is set if lane `i` is active.
    #[must_use]
    pub fn active_mask(&self) -> u16 {
        (0..16)
            .filter(|&i| self.valid.0[i] != 0)
            .fold(0, |m, i| m | (1 << i))
    }

    /// The valid mask of lanes `first..first + 8` as a packet of 8, unless none is active.
    #[inline]
    fn valid_half(&self, first: usize) -> Option<ValidMask8> {
        let lanes = &self.valid.0[first..first + 8];
        lanes.iter().any(|&v| v != 0).then(|| {
            let mut valid = ValidMask8([0; 8]);
            valid.0.copy_from_slice(lanes);
            valid
        })
    }

    /// Hands each half of the packet that has an active lane to `trace` as a packet of 8
    /// (valid mask and rays with their hit records), and copies back what it wrote.
    fn by_halves(&mut self, mut trace: impl FnMut(*const i32, &mut sys::RTCRayHit8)) {
        for first in [0, 8] {
            let Some(valid) = self.valid_half(first) else {
                continue;
            };
            let mut packet8 = sys::RTCRayHit8 {
                ray: lanes_of(&self.rayhit.ray, first),
                hit: hit_lanes_of(&self.rayhit.hit, first),
            };
            trace(valid.0.as_ptr(), &mut packet8);
            self.rayhit.ray.tfar[first..first + 8].copy_from_slice(&packet8.ray.tfar);
            put_hit_lanes(&mut self.rayhit.hit, first, &packet8.hit);
        }
    }

    /// [`RayPacket16::by_halves`] for occlusion, which reads and writes only the rays (their
    /// `tfar`): the hit records stay where they are.
    fn rays_by_halves(&mut self, mut trace: impl FnMut(*const i32, &mut sys::RTCRay8)) {
        for first in [0, 8] {
            let Some(valid) = self.valid_half(first) else {
                continue;
            };
            let mut ray8 = lanes_of(&self.rayhit.ray, first);
            trace(valid.0.as_ptr(), &mut ray8);
            self.rayhit.ray.tfar[first..first + 8].copy_from_slice(&ray8.tfar);
        }
    }
}

#[repr(C, align(64))]
struct ValidMask8([i32; 8]);

/// Lanes `first..first + 8` of one field of a 16-wide packet.
fn half<T: Copy>(lanes: &[T; 16], first: usize) -> [T; 8] {
    std::array::from_fn(|i| lanes[first + i])
}

/// Lanes `first..first + 8` of a 16-wide packet's rays.
fn lanes_of(ray: &sys::RTCRay16, first: usize) -> sys::RTCRay8 {
    sys::RTCRay8 {
        org_x: half(&ray.org_x, first),
        org_y: half(&ray.org_y, first),
        org_z: half(&ray.org_z, first),
        tnear: half(&ray.tnear, first),
        dir_x: half(&ray.dir_x, first),
        dir_y: half(&ray.dir_y, first),
        dir_z: half(&ray.dir_z, first),
        time: half(&ray.time, first),
        tfar: half(&ray.tfar, first),
        mask: half(&ray.mask, first),
        id: half(&ray.id, first),
        flags: half(&ray.flags, first),
    }
}

/// Lanes `first..first + 8` of a 16-wide packet's hit records.
fn hit_lanes_of(hit: &sys::RTCHit16, first: usize) -> sys::RTCHit8 {
    sys::RTCHit8 {
        Ng_x: half(&hit.Ng_x, first),
        Ng_y: half(&hit.Ng_y, first),
        Ng_z: half(&hit.Ng_z, first),
        u: half(&hit.u, first),
        v: half(&hit.v, first),
        primID: half(&hit.primID, first),
        geomID: half(&hit.geomID, first),
        instID: hit.instID.map(|level| half(&level, first)),
    }
}

/// Writes a packet of 8's hit records back into lanes `first..first + 8`.
fn put_hit_lanes(hit: &mut sys::RTCHit16, first: usize, from: &sys::RTCHit8) {
    fn put<T: Copy>(lanes: &mut [T; 16], first: usize, from: &[T; 8]) {
        lanes[first..first + 8].copy_from_slice(from);
    }
    put(&mut hit.Ng_x, first, &from.Ng_x);
    put(&mut hit.Ng_y, first, &from.Ng_y);
    put(&mut hit.Ng_z, first, &from.Ng_z);
    put(&mut hit.u, first, &from.u);
    put(&mut hit.v, first, &from.v);
    put(&mut hit.primID, first, &from.primID);
    put(&mut hit.geomID, first, &from.geomID);
    for (level, from_level) in hit.instID.iter_mut().zip(&from.instID) {
        put(level, first, from_level);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{align_of, offset_of, size_of};

    /// Numbers printed by a gcc program (`sizeof`/`_Alignof`/`offsetof`)
    /// compiled against the installed Embree 3.13.5 headers.
    #[test]
    fn layouts_match_c_headers() {
        use sys::*;
        assert_eq!((size_of::<RTCRay>(), align_of::<RTCRay>()), (48, 16));
        assert_eq!(offset_of!(RTCRay, tnear), 12);
        assert_eq!(offset_of!(RTCRay, dir_x), 16);
        assert_eq!(offset_of!(RTCRay, time), 28);
        assert_eq!(offset_of!(RTCRay, tfar), 32);
        assert_eq!(offset_of!(RTCRay, mask), 36);
        assert_eq!(offset_of!(RTCRay, id), 40);
        assert_eq!(offset_of!(RTCRay, flags), 44);

        assert_eq!((size_of::<RTCHit>(), align_of::<RTCHit>()), (32, 16));
        assert_eq!(offset_of!(RTCHit, u), 12);
        assert_eq!(offset_of!(RTCHit, v), 16);
        assert_eq!(offset_of!(RTCHit, primID), 20);
        assert_eq!(offset_of!(RTCHit, geomID), 24);
        assert_eq!(offset_of!(RTCHit, instID), 28);

        assert_eq!((size_of::<RTCRayHit>(), align_of::<RTCRayHit>()), (80, 16));
        assert_eq!(offset_of!(RTCRayHit, hit), 48);

        assert_eq!((size_of::<RTCRay16>(), align_of::<RTCRay16>()), (768, 64));
        assert_eq!(offset_of!(RTCRay16, tnear), 192);
        assert_eq!(offset_of!(RTCRay16, dir_x), 256);
        assert_eq!(offset_of!(RTCRay16, tfar), 512);
        assert_eq!(offset_of!(RTCRay16, mask), 576);
        assert_eq!(offset_of!(RTCRay16, flags), 704);

        assert_eq!((size_of::<RTCHit16>(), align_of::<RTCHit16>()), (512, 64));
        assert_eq!(offset_of!(RTCHit16, primID), 320);
        assert_eq!(offset_of!(RTCHit16, geomID), 384);
        assert_eq!(offset_of!(RTCHit16, instID), 448);
        assert_eq!(
            (size_of::<RTCRayHit16>(), align_of::<RTCRayHit16>()),
            (1280, 64)
        );
        assert_eq!(offset_of!(RTCRayHit16, hit), 768);

        // C aligns the packets of 8 to 32 bytes; ours are aligned to 64, with the same layout.
        assert_eq!(size_of::<RTCRay8>(), 384);
        assert_eq!(offset_of!(RTCRay8, dir_x), 128);
        assert_eq!(offset_of!(RTCRay8, tfar), 256);
        assert_eq!(size_of::<RTCHit8>(), 256);
        assert_eq!(offset_of!(RTCHit8, geomID), 192);
        assert_eq!(
            (size_of::<RTCRayHit8>(), offset_of!(RTCRayHit8, hit)),
            (640, 384)
        );

        assert_eq!(
            (
                size_of::<RTCIntersectContext>(),
                align_of::<RTCIntersectContext>()
            ),
            (24, 8)
        );
        assert_eq!(offset_of!(RTCIntersectContext, filter), 8);
        assert_eq!(offset_of!(RTCIntersectContext, instID), 16);

        assert_eq!(align_of::<ValidMask>(), 64);
        assert_eq!(offset_of!(RayPacket16, rayhit) % 64, 0);
    }

    fn device() -> Device {
        Device::new(2).expect("embree device")
    }

    /// Unit quad in the z = 0 plane, x and y in [0, 1].
    fn quad_scene() -> (Scene, u32, u32) {
        let (b, quad, far) = quad_builder();
        (b.commit().expect("commit"), quad, far)
    }

    /// [`quad_scene`]'s geometry, not yet built.
    fn quad_builder() -> (SceneBuilder, u32, u32) {
        let mut b = SceneBuilder::new(&device()).expect("scene");
        let quad = b
            .add_triangle_mesh(
                &[
                    [0.0, 0.0, 0.0],
                    [1.0, 0.0, 0.0],
                    [1.0, 1.0, 0.0],
                    [0.0, 1.0, 0.0],
                ],
                &[[0, 1, 2], [0, 2, 3]],
            )
            .expect("quad");
        // A second geometry further along +z, to check geom ids and closest hit.
        let far = b
            .add_triangle_mesh(
                &[[-5.0, -5.0, 3.0], [5.0, -5.0, 3.0], [0.0, 5.0, 3.0]],
                &[[0, 1, 2]],
            )
            .expect("tri");
        (b, quad, far)
    }

    #[test]
    fn an_unsealed_scene_blocks_what_its_triangles_cover() {
        let scene = quad_builder().0.commit_unsealed().expect("commit");
        let down = [0.0, 0.0, -1.0];
        // Inside each of the quad's two triangles, away from their shared edge.
        assert!(scene.occluded([0.7, 0.2, 1.0], down, 0.0, 10.0));
        assert!(scene.occluded([0.2, 0.7, 1.0], down, 0.0, 10.0));
        assert!(!scene.occluded([1.5, 0.5, 1.0], down, 0.0, 10.0));
        assert!(!scene.occluded([0.7, 0.2, 1.0], down, 0.0, 0.5));
    }

    #[test]
    fn quad_blocks_ray_through_it_only() {
        let (scene, _, _) = quad_scene();
        let down = [0.0, 0.0, -1.0];
        assert!(scene.occluded([0.5, 0.5, 1.0], down, 0.0, 10.0));
        assert!(!scene.occluded([1.5, 0.5, 1.0], down, 0.0, 10.0));
        // Segment ending before the quad.
        assert!(!scene.occluded([0.5, 0.5, 1.0], down, 0.0, 0.5));
        // Invalid segments hit nothing instead of reaching Embree.
        assert!(!scene.occluded([0.5, 0.5, 1.0], down, 2.0, 1.0));
        assert!(!scene.occluded([f32::NAN, 0.5, 1.0], down, 0.0, 10.0));
    }

    /// Rays through the edge the quad's two triangles share, at a slant, meet the quad: none
    /// slips through the seam.
    #[test]
    fn no_ray_slips_through_the_seam_between_triangles() {
        let (scene, _, _) = quad_scene();
        let slant = [0.3f32, -0.2, -0.93];
        let len = slant.iter().map(|c| c * c).sum::<f32>().sqrt();
        let dir = slant.map(|c| c / len);
        for i in 1..1000 {
            let t = i as f32 / 1000.0;
            // The point on the diagonal, and a start 2 units back along the ray.
            let org = [t - 2.0 * dir[0], t - 2.0 * dir[1], -2.0 * dir[2]];
            assert!(
                scene.occluded(org, dir, 0.0, 10.0),
                "slipped through at {t}"
            );
        }
    }

    #[test]
    fn device_options_follow_ours() {
        assert_eq!(device_config(3, ""), "threads=3,set_affinity=0");
        assert_eq!(
            device_config(3, " isa=sse4.2 "),
            "threads=3,set_affinity=0,isa=sse4.2"
        );
        // SSE2 kernels run on every x86-64 CPU.
        let sse2 = Device::with_options(1, "isa=sse2").expect("SSE2 device");
        let mut b = SceneBuilder::new(&sse2).expect("scene");
        b.add_triangle_mesh(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0, 1, 2]],
        )
        .expect("mesh");
        let scene = b.commit().expect("commit");
        assert!(scene.occluded([0.25, 0.25, 1.0], [0.0, 0.0, -1.0], 0.0, 2.0));
        // An option Embree rejects comes back as an error.
        assert!(Device::with_options(1, "isa=").is_err());
    }

    #[test]
    fn intersect_reports_t_and_geom_id() {
        let (scene, quad, far) = quad_scene();
        assert_ne!(quad, far);
        let hit = scene
            .intersect([0.25, 0.75, -2.0], [0.0, 0.0, 1.0], 0.0, f32::INFINITY)
            .expect("hit quad");
        assert_eq!(hit.geom_id, quad);
        assert_eq!(hit.prim_id, 1);
        assert!((hit.t - 2.0).abs() < 1e-5, "t = {}", hit.t);
        assert!(hit.ng[2] > 0.0, "counter-clockwise winding faces +z");
        // Starting past the quad reaches the far triangle.
        let hit = scene
            .intersect([0.25, 0.75, 1.0], [0.0, 0.0, 1.0], 0.0, f32::INFINITY)
            .expect("hit far tri");
        assert_eq!((hit.geom_id, hit.prim_id), (far, 0));
        assert!((hit.t - 2.0).abs() < 1e-5);
        assert!(
            scene
                .intersect([9.0, 9.0, -1.0], [0.0, 0.0, 1.0], 0.0, 100.0)
                .is_none()
        );
    }

    /// A fuzzed BSP with a vertex at 1e19 made Embree abort on its own validity assertion: finite
    /// rays past its largest coordinate must stay on our side, in a packet's inactive lanes too.
    #[test]
    fn rays_past_embrees_largest_coordinate_hit_nothing() {
        let (scene, _, _) = quad_scene();
        let up = [0.0, 0.0, 1.0];
        let far_away = [0.5, 1.0e19, -1.0];
        assert!(scene.intersect(far_away, up, 0.0, 10.0).is_none());
        assert!(!scene.occluded(far_away, up, 0.0, 10.0));
        assert!(!scene.occluded([0.5, 0.5, -1.0], [0.0, 0.0, 1.0e19], 0.0, 10.0));
        let mut packet = RayPacket16::new();
        packet.set(0, far_away, up, 0.0, 10.0);
        packet.set(1, [0.5, 0.5, -1.0], up, 0.0, 10.0);
        assert_eq!(packet.active_mask(), 0b10);
        for coherent in [true, false] {
            let hits = scene.first_hit_geom16(&mut packet.clone(), coherent);
            assert_eq!(hits[0], sys::RTC_INVALID_GEOMETRY_ID);
            assert_ne!(hits[1], sys::RTC_INVALID_GEOMETRY_ID);
            assert_eq!(scene.occluded16(&mut packet.clone(), coherent), 0b10);
        }
    }

    #[test]
    fn rejects_out_of_range_index() {
        let mut b = SceneBuilder::new(&device()).expect("scene");
        let err = b
            .add_triangle_mesh(&[[0.0; 3]; 3], &[[0, 1, 3]])
            .unwrap_err();
        assert!(matches!(err, EmbreeError::InvalidInput(_)), "{err}");
    }

    /// Tiny xorshift so the test needs no dependencies.
    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn v(&mut self, s: f32) -> [f32; 3] {
            [
                (self.f() * 2.0 - 1.0) * s,
                (self.f() * 2.0 - 1.0) * s,
                (self.f() * 2.0 - 1.0) * s,
            ]
        }
    }

    /// Axis-aligned box [-1, 1]^3 as 12 triangles, on `device`.
    fn box_scene(device: &Device) -> Scene {
        let verts: Vec<[f32; 3]> = (0..8)
            .map(|i| {
                [
                    (i & 1) as f32 * 2.0 - 1.0,
                    ((i >> 1) & 1) as f32 * 2.0 - 1.0,
                    (i >> 2) as f32 * 2.0 - 1.0,
                ]
            })
            .collect();
        let faces = [
            [0, 1, 3, 2],
            [4, 6, 7, 5],
            [0, 4, 5, 1],
            [2, 3, 7, 6],
            [0, 2, 6, 4],
            [1, 5, 7, 3],
        ];
        let tris: Vec<[u32; 3]> = faces
            .iter()
            .flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]])
            .collect();
        let mut b = SceneBuilder::new(device).expect("scene");
        b.add_triangle_mesh(&verts, &tris).expect("box");
        b.commit().expect("commit")
    }

    /// The machine's own kernels, and SSE2 kernels, which take 16-wide packets by halves.
    fn devices_native_and_by_halves() -> [Device; 2] {
        let sse2 = Device::with_options(1, "isa=sse2").expect("SSE2 device");
        assert!(!sse2.inner.native16);
        [device(), sse2]
    }

    /// Random rays around the box, some lanes left inactive to exercise the valid mask: the
    /// packet and the `(org, dir, tfar)` of each active lane.
    fn random_packet(rng: &mut Rng, round: usize) -> (RayPacket16, [Option<RandomRay>; 16]) {
        let mut packet = RayPacket16::new();
        let mut rays = [None; 16];
        for (lane, ray) in rays.iter_mut().enumerate() {
            if (round + lane).is_multiple_of(7) {
                continue;
            }
            let (org, dir, tfar) = (rng.v(4.0), rng.v(1.0), rng.f() * 8.0);
            packet.set(lane, org, dir, 0.0, tfar);
            *ray = Some((org, dir, tfar));
        }
        (packet, rays)
    }

    type RandomRay = ([f32; 3], [f32; 3], f32);

    #[test]
    fn occluded16_matches_occluded() {
        for device in devices_native_and_by_halves() {
            let scene = box_scene(&device);
            let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
            let (mut hits, mut misses) = (0, 0);
            for round in 0..200 {
                let (mut packet, rays) = random_packet(&mut rng, round);
                let expected = (0..16)
                    .filter(|&lane| {
                        rays[lane]
                            .is_some_and(|(org, dir, tfar)| scene.occluded(org, dir, 0.0, tfar))
                    })
                    .fold(0u16, |m, lane| m | 1 << lane);
                let got = scene.occluded16(&mut packet, round % 2 == 0);
                assert_eq!(got, expected, "round {round}");
                assert_eq!(got & !packet.active_mask(), 0);
                hits += expected.count_ones();
                misses += packet.active_mask().count_ones() - expected.count_ones();
            }
            // Make sure the random rays actually exercise both outcomes.
            assert!(hits > 100 && misses > 100, "hits {hits} misses {misses}");
        }
    }

    #[test]
    fn first_hits16_match_intersect() {
        for device in devices_native_and_by_halves() {
            let scene = box_scene(&device);
            let mut rng = Rng(0x2545_f491_4f6c_dd1d);
            let mut hits = 0;
            for round in 0..200 {
                let (mut packet, rays) = random_packet(&mut rng, round);
                let got = scene.first_hits16(&mut packet, round % 2 == 0);
                for (lane, ray) in rays.iter().enumerate() {
                    let expected =
                        ray.and_then(|(org, dir, tfar)| scene.intersect(org, dir, 0.0, tfar));
                    match expected {
                        Some(hit) => {
                            hits += 1;
                            assert_eq!(got[lane], (hit.geom_id, hit.prim_id), "round {round}");
                            // Packet and single-ray kernels may round differently.
                            let dt = (packet.tfar(lane) - hit.t).abs();
                            assert!(dt <= 1e-5 * hit.t.max(1.0), "round {round} lane {lane}");
                        }
                        None => assert_eq!(got[lane].0, sys::RTC_INVALID_GEOMETRY_ID),
                    }
                }
            }
            assert!(hits > 100, "hits {hits}");
        }
    }

    #[test]
    fn first_hit_geom16_matches_intersect() {
        let (scene, quad, far) = quad_scene();
        let mut packet = RayPacket16::new();
        let up = [0.0, 0.0, 1.0];
        packet.set(0, [0.5, 0.5, -1.0], up, 0.0, 100.0);
        packet.set(1, [0.5, 0.5, 1.0], up, 0.0, 100.0);
        packet.set(2, [9.0, 9.0, -1.0], up, 0.0, 100.0);
        packet.set(3, [0.5, 0.5, -1.0], up, 0.0, 0.5);
        let ids = scene.first_hit_geom16(&mut packet, true);
        assert_eq!(ids[0], quad);
        assert_eq!(ids[1], far);
        assert_eq!(ids[2], sys::RTC_INVALID_GEOMETRY_ID);
        assert_eq!(ids[3], sys::RTC_INVALID_GEOMETRY_ID, "segment stops short");
        assert!(
            ids[4..]
                .iter()
                .all(|&id| id == sys::RTC_INVALID_GEOMETRY_ID)
        );
    }

    #[test]
    fn scene_is_send_sync_and_queryable_from_threads() {
        fn assert_send_sync<T: Send + Sync>() {}
        assert_send_sync::<Scene>();
        assert_send_sync::<Device>();
        let (scene, _, _) = quad_scene();
        std::thread::scope(|s| {
            for i in 0..4 {
                let scene = &scene;
                s.spawn(move || {
                    let x = 0.1 + 0.2 * i as f32;
                    assert!(scene.occluded([x, 0.5, 1.0], [0.0, 0.0, -1.0], 0.0, 10.0));
                });
            }
        });
    }

    #[test]
    fn embree_errors_carry_code_and_message() {
        let dev = device();
        // SAFETY: live device; the geometry is released by the guard.
        let geom = GeometryGuard(unsafe {
            sys::rtcNewGeometry(dev.inner.raw, sys::RTC_GEOMETRY_TYPE_TRIANGLE)
        });
        // A 3-byte stride is not 4-byte aligned, which Embree rejects.
        let err = set_buffer(
            &dev.inner,
            geom.0,
            sys::RTC_BUFFER_TYPE_VERTEX,
            sys::RTC_FORMAT_FLOAT3,
            &[[0u8; 3]],
        )
        .unwrap_err();
        let EmbreeError::Api { code, message, .. } = &err else {
            panic!("unexpected {err:?}");
        };
        assert_eq!(*code, sys::RTC_ERROR_INVALID_OPERATION, "{err}");
        assert!(message.is_some(), "{err}");
        // The error is consumed: the next check on this thread is clean.
        assert!(dev.inner.check("noop").is_ok());
    }

    #[test]
    fn empty_meshes_are_allowed() {
        let mut b = SceneBuilder::new(&device()).expect("scene");
        assert_eq!(b.add_triangle_mesh(&[], &[]), Ok(0));
        let scene = b.commit().expect("commit");
        assert!(!scene.occluded([0.0; 3], [1.0, 0.0, 0.0], 0.0, 1.0));
    }
}
