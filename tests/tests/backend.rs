//! The Vulkan backend on the real driver: device creation, memory round trips, a compute
//! shader checked exactly, and the validation canary.
use kage::backend::{
    vk, Binding, BindingKind, Buffer, BufferDesc, BufferUsage, ComputePipeline, Context, ContextDesc,
    MemoryLocation,
};
use kage::layouts::{bytes_of, bytes_of_slice, constants, spirv, ShCoeffs, ShProjectPush};
use kage::pass::{FrameExecutor, Pass};
use kage_tests::Validated;

#[test]
fn device_is_created_and_described() {
    let ctx = Validated::new();
    let info = ctx.info();
    assert!(!info.name.is_empty());
    assert!(info.features.iter().filter(|(n, _)| n.ends_with("(required)")).all(|(_, present)| *present));
}

#[test]
fn unknown_device_name_is_a_clear_error() {
    let err = Context::new(&ContextDesc { validation: false, device: Some("no such gpu 1234".into()) })
        .err()
        .expect("no device has that name");
    let text = err.to_string();
    assert!(text.contains("no such gpu 1234") && text.contains("devices:"), "{text}");
}

#[test]
fn upload_and_readback_round_trip() {
    let ctx = Validated::new();
    let data: Vec<u8> = (0..100_003u32).map(|i| (i * 7 + 3) as u8).collect();
    let buffer = Buffer::with_data(&ctx, "round_trip", BufferUsage::TRANSFER_SRC, &data).unwrap();
    assert_eq!(buffer.read().unwrap(), data);
}

/// sh_reduce.comp adds per-workgroup partials; with small integers every float sum is exact, so
/// the result must equal the CPU sum bit for bit.
#[test]
fn compute_shader_result_is_exact() {
    let ctx = Validated::new();
    let count = 1000u32;
    let partials: Vec<ShCoeffs> = (0..count)
        .map(|k| {
            let mut p = ShCoeffs::default();
            for (i, c) in p.c.iter_mut().enumerate() {
                *c = [(k % 17) as f32, i as f32, (k * i as u32 % 5) as f32, 0.0];
            }
            p
        })
        .collect();
    let storage = BufferUsage::STORAGE;
    let input = Buffer::with_data(&ctx, "partials", storage, bytes_of_slice(&partials)).unwrap();
    let output = Buffer::new(
        &ctx,
        &BufferDesc {
            name: "sum",
            size: size_of::<ShCoeffs>() as u64,
            usage: storage | BufferUsage::TRANSFER_SRC,
            location: MemoryLocation::GpuOnly,
        },
    )
    .unwrap();
    let pipeline = ComputePipeline::new(
        &ctx,
        "sh_reduce",
        spirv::SH_REDUCE_COMP,
        &[BindingKind::StorageBuffer, BindingKind::StorageBuffer],
        size_of::<ShProjectPush>() as u32,
    )
    .unwrap();
    let push = ShProjectPush { size: [count, 0, 0, 0] };
    let mut executor = FrameExecutor::new(&ctx, "exact").unwrap();
    let timings = executor
        .run(vec![Pass::new("reduce", |cmd| {
            pipeline.dispatch(
                cmd,
                &[Binding::Storage(&input), Binding::Storage(&output)],
                bytes_of(&push),
                [1, 1, 1],
            )
        })])
        .unwrap();
    assert_eq!(timings.len(), 1);
    assert_eq!(constants::SH_COEFFS, 9);

    let bytes = output.read().unwrap();
    let got: Vec<f32> = bytes.chunks_exact(4).map(|b| f32::from_ne_bytes([b[0], b[1], b[2], b[3]])).collect();
    for i in 0..9 {
        let expected = [
            partials.iter().map(|p| p.c[i][0] as f64).sum::<f64>(),
            partials.iter().map(|p| p.c[i][1] as f64).sum::<f64>(),
            partials.iter().map(|p| p.c[i][2] as f64).sum::<f64>(),
        ];
        for k in 0..3 {
            assert_eq!(got[i * 4 + k] as f64, expected[k], "coefficient {i}, channel {k}");
        }
    }
}

/// A pass's reads and writes are the buffers it binds, read or written as its shader declares
/// them (sh_reduce reads its partials `readonly` and writes its result): a pass that reads what
/// a later pass of the frame writes is refused before anything is submitted, naming both, and
/// the executor runs the same passes in order afterwards.
#[test]
fn frame_with_unordered_passes_is_rejected() {
    let ctx = Validated::new();
    let one = size_of::<ShCoeffs>() as u64;
    let storage = BufferUsage::STORAGE;
    let input = Buffer::with_data(&ctx, "input", storage, bytes_of(&ShCoeffs::default())).unwrap();
    let buffer = |name| {
        Buffer::new(&ctx, &BufferDesc { name, size: one, usage: storage, location: MemoryLocation::GpuOnly })
            .unwrap()
    };
    let (middle, result) = (buffer("middle"), buffer("result"));
    let kinds = [BindingKind::StorageBuffer, BindingKind::StorageBuffer];
    let push_size = size_of::<ShProjectPush>() as u32;
    let pipeline = ComputePipeline::new(&ctx, "sh_reduce", spirv::SH_REDUCE_COMP, &kinds, push_size).unwrap();
    let push = ShProjectPush { size: [1, 0, 0, 0] };
    let reduce = |name, from: &'static str| {
        let (from, to) = if from == "input" { (&input, &middle) } else { (&middle, &result) };
        let pipeline = &pipeline;
        Pass::new(name, move |cmd| {
            pipeline.dispatch(
                cmd,
                &[Binding::Storage(from), Binding::Storage(to)],
                bytes_of(&push),
                [1, 1, 1],
            )
        })
    };
    let mut executor = FrameExecutor::new(&ctx, "order").unwrap();
    let err = executor.run(vec![reduce("consumer", "middle"), reduce("producer", "input")]).unwrap_err();
    assert!(err.to_string().contains("pass consumer reads middle before pass producer writes it"), "{err}");
    executor.run(vec![reduce("producer", "input"), reduce("consumer", "middle")]).unwrap();
}

/// The canary: a deliberate misuse must reach the collected messages, or every other test's
/// "no validation message" would prove nothing.
#[test]
fn planted_validation_error_is_caught() {
    let ctx = Context::new(&ContextDesc { validation: true, device: None }).unwrap();
    // Usage flags must not be empty (VUID-VkBufferCreateInfo-usage-requiredbitmask).
    let info = vk::BufferCreateInfo::default().size(64).usage(vk::BufferUsageFlags::empty());
    // SAFETY: deliberately invalid create info; lavapipe creates the buffer anyway, and it is
    // destroyed right after.
    let buffer = unsafe { ctx.device().create_buffer(&info, None) }.unwrap();
    // SAFETY: the buffer is unused.
    unsafe { ctx.device().destroy_buffer(buffer, None) };
    let messages = ctx.take_validation_messages();
    assert!(
        messages.iter().any(|m| m.contains("VUID-VkBufferCreateInfo-usage-requiredbitmask")),
        "the planted error was not reported: {messages:?}"
    );
    assert!(ctx.take_validation_messages().is_empty(), "take() clears the log");
}
