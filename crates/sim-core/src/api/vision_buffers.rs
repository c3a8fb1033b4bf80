//! simVision's buffers 1 and 2 beside a sensor's work image (see
//! `gantry_world::vision`'s `buffers.rs`): copies, swaps, and arithmetic between the
//! work image and buffer 1. Each takes the sensor (`sim.handle_self` for the calling
//! script's object), which must have a work image (`simVision.sensorImgToWorkImg`
//! first), and returns nothing.

use super::vision::sensor_handle;
use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::error::SimError;
use crate::sim::Sim;
use crate::vision::buffers::{Buffer, BufferOp};
use crate::vision::{self, WorkImage};

/// The `simVision.*` buffer functions, in alphabetical order.
pub(super) const SIM_VISION_FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "addBuffer1ToWorkImg",
        call: ApiFn::Sim(add_buffer1_to_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "addWorkImgToBuffer1",
        call: ApiFn::Sim(add_work_img_to_buffer1),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "buffer1ToWorkImg",
        call: ApiFn::Sim(buffer1_to_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "buffer2ToWorkImg",
        call: ApiFn::Sim(buffer2_to_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "multiplyWorkImgWithBuffer1",
        call: ApiFn::Sim(multiply_work_img_with_buffer1),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "subtractBuffer1FromWorkImg",
        call: ApiFn::Sim(subtract_buffer1_from_work_img),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "subtractWorkImgFromBuffer1",
        call: ApiFn::Sim(subtract_work_img_from_buffer1),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "swapBuffers",
        call: ApiFn::Sim(swap_buffers),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "swapWorkImgWithBuffer1",
        call: ApiFn::Sim(swap_work_img_with_buffer1),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "workImgToBuffer1",
        call: ApiFn::Sim(work_img_to_buffer1),
        cost: Cost::Long,
    },
    ApiFunction {
        name: "workImgToBuffer2",
        call: ApiFn::Sim(work_img_to_buffer2),
        cost: Cost::Long,
    },
];

/// Runs `f` on the work image of the sensor in argument 0.
fn on_work(
    sim: &mut Sim,
    ctx: &CallContext<'_>,
    a: &Args<'_>,
    f: impl FnOnce(&mut WorkImage<'_>),
) -> Result<Ret, SimError> {
    let h = sensor_handle(ctx, a, 0)?;
    f(&mut vision::work(&sim.world, &mut sim.vision, h)?);
    Ok(Vec::new())
}

/// `simVision.workImgToBuffer1(h)`: a copy of the work image in buffer 1.
fn work_img_to_buffer1(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.to_buffer(Buffer::One))
}

/// `simVision.workImgToBuffer2(h)`: a copy of the work image in buffer 2.
fn work_img_to_buffer2(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.to_buffer(Buffer::Two))
}

/// `simVision.buffer1ToWorkImg(h)`: buffer 1 (black if never written) becomes the work
/// image.
fn buffer1_to_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.from_buffer(Buffer::One))
}

/// `simVision.buffer2ToWorkImg(h)`: buffer 2 (black if never written) becomes the work
/// image.
fn buffer2_to_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.from_buffer(Buffer::Two))
}

/// `simVision.swapBuffers(h)`: buffers 1 and 2 trade places.
fn swap_buffers(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.swap_buffers())
}

/// `simVision.swapWorkImgWithBuffer1(h)`: the work image and buffer 1 trade places.
fn swap_work_img_with_buffer1(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.swap_with_buffer1())
}

/// `simVision.addWorkImgToBuffer1(h)`: buffer 1 += work image, at most 1.
fn add_work_img_to_buffer1(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.combine_with_buffer1(BufferOp::AddWorkToBuffer1))
}

/// `simVision.subtractWorkImgFromBuffer1(h)`: buffer 1 -= work image, at least 0.
fn subtract_work_img_from_buffer1(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| {
        w.combine_with_buffer1(BufferOp::SubtractWorkFromBuffer1)
    })
}

/// `simVision.addBuffer1ToWorkImg(h)`: work image += buffer 1, at most 1.
fn add_buffer1_to_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.combine_with_buffer1(BufferOp::AddBuffer1ToWork))
}

/// `simVision.subtractBuffer1FromWorkImg(h)`: work image -= buffer 1, at least 0.
fn subtract_buffer1_from_work_img(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| {
        w.combine_with_buffer1(BufferOp::SubtractBuffer1FromWork)
    })
}

/// `simVision.multiplyWorkImgWithBuffer1(h)`: work image *= buffer 1, at most 1.
fn multiply_work_img_with_buffer1(sim: &mut Sim, ctx: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    on_work(sim, ctx, a, |w| w.combine_with_buffer1(BufferOp::MultiplyWorkByBuffer1))
}
