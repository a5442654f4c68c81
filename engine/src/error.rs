//! The engine's error type. Each variant says whose fault the failure is ([`Error::fault`]): the
//! caller's values, a file's content, the device, or a bug in Kage. The backend maps every
//! failed Vulkan call (`backend/vk_error.rs`) so that the failure classes a host cares about
//! (out of memory, device lost) stay distinguishable.

pub type Result<T, E = Error> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("the Vulkan loader could not be opened: {0}")]
    Loader(String),
    #[error("no usable Vulkan device: {0}")]
    NoDevice(String),
    #[error("the device lacks {0}, which Kage needs")]
    Unsupported(String),
    #[error("out of device memory in {call}")]
    OutOfDeviceMemory { call: &'static str },
    #[error("out of host memory in {call}")]
    OutOfHostMemory { call: &'static str },
    /// One resource that the device cannot hold: beyond its size limit for the format, or no
    /// memory left for it. Like the two above, a request to retry with smaller settings.
    #[error("out of device memory for {name} ({bytes} bytes): {reason}")]
    OutOfDeviceMemoryFor { name: String, bytes: u64, reason: String },
    /// Host memory for data a caller sized (see [`crate::host_memory`]) could not be had.
    #[error(transparent)]
    OutOfHostMemoryFor(#[from] crate::host_memory::OutOfHostMemory),
    #[error("the Vulkan device was lost in {call}")]
    DeviceLost { call: &'static str },
    /// Any other failed Vulkan call; `result` names its `VkResult`.
    #[error("{call} failed: {result}")]
    Vulkan { call: &'static str, result: String },
    #[error("GPU memory allocation for {name} failed: {message}")]
    Allocation { name: String, message: String },
    #[error("timed out waiting for the GPU in {0}")]
    Timeout(&'static str),
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error(transparent)]
    Image(#[from] crate::imageio::ImageIoError),
    #[error(transparent)]
    Probes(#[from] ProbeError),
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The caller's progress callback asked to stop.
    #[error("{0} was cancelled by the caller")]
    Cancelled(&'static str),
    /// A bug in Kage, not in what it was given: a pass reading what no pass wrote, a write past
    /// a buffer the engine sized itself.
    #[error("internal error (please report): {0}")]
    Internal(String),
}

/// Whose fault a failure is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fault {
    /// A value the caller passed (an argument, a scene built in code).
    Caller,
    /// A file that could not be read or is malformed.
    File,
    /// The Vulkan loader or device: missing, lacking a feature, out of memory, lost; or the
    /// machine's own memory running out.
    Device,
    /// Kage itself.
    Internal,
}

impl Error {
    pub fn fault(&self) -> Fault {
        match self {
            Error::Loader(_)
            | Error::NoDevice(_)
            | Error::Unsupported(_)
            | Error::OutOfDeviceMemory { .. }
            | Error::OutOfHostMemory { .. }
            | Error::OutOfDeviceMemoryFor { .. }
            | Error::OutOfHostMemoryFor(_)
            | Error::DeviceLost { .. }
            | Error::Vulkan { .. }
            | Error::Allocation { .. }
            | Error::Timeout(_) => Fault::Device,
            Error::Scene(e) if e.out_of_memory() => Fault::Device,
            Error::Scene(e) if e.file().is_some() => Fault::File,
            Error::Image(e) if e.by_caller() => Fault::Caller,
            Error::Image(_) => Fault::File,
            Error::Probes(ProbeError::FitDiverged { .. }) => Fault::Internal,
            Error::Scene(_) | Error::Probes(_) | Error::InvalidArgument(_) | Error::Cancelled(_) => {
                Fault::Caller
            }
            Error::Internal(_) => Fault::Internal,
        }
    }
}

/// What can be wrong with a light probe set or a lookup point (the probes technique).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProbeError {
    #[error("not a probe file {{\"positions\": [[x, y, z], ...]}}: {problem}")]
    File { problem: String },
    #[error("probe {index} at {position:?}: {problem}")]
    BadPosition { index: usize, position: [f64; 3], problem: &'static str },
    #[error("lookup point {position:?}: {problem}")]
    BadPoint { position: [f64; 3], problem: &'static str },
    #[error(
        "{distinct} distinct probe position(s) among the {total} given: a tetrahedralization needs at least 4"
    )]
    TooFew { distinct: usize, total: usize },
    #[error("all {distinct} distinct probe positions lie {shape}: a tetrahedralization needs 4 that do not lie in one plane")]
    Flat { distinct: usize, shape: &'static str },
    #[error("the least-squares fit of {probes} probes' SH did not converge")]
    FitDiverged { probes: usize },
    #[error("{total} probes given: at most {max} are supported")]
    TooMany { total: usize, max: usize },
    #[error(
        "the Delaunay tetrahedralization of {points} probes needs more than {max} tetrahedra: probes \
         on a few lines or curves (two skew lines) make quadratically many; spread them in 3D"
    )]
    TooManyTetrahedra { points: usize, max: usize },
}
