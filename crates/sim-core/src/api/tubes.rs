//! `sim.tubeOpen`, `sim.tubeWrite`, `sim.tubeRead`, `sim.tubeStatus`, `sim.tubeClose`:
//! V-REP's pipes between scripts ([`crate::tubes`]). `sim.tubeRead`'s blocking form is
//! the Lua host's (`lua/threads.lua`): it waits a step at a time in a threaded script.

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::error::SimError;
use crate::sim::Sim;

/// The tube functions.
pub const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "tubeClose",
        call: ApiFn::Sim(tube_close),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "tubeOpen",
        call: ApiFn::Sim(tube_open),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "tubeRead",
        call: ApiFn::Sim(tube_read),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "tubeStatus",
        call: ApiFn::Sim(tube_status),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "tubeWrite",
        call: ApiFn::Sim(tube_write),
        cost: Cost::Quick,
    },
];

/// `sim.tubeOpen(dataHeader, dataName, readBufferSize)`: a tube end's handle.
fn tube_open(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let h = sim.tubes.open(a.int(0)?, a.str(1)?, a.opt_int(2, 1)?);
    Ok(vec![Value::Int(h)])
}

/// `sim.tubeWrite(tubeHandle, data)`: 1 when the other end is open (the packet went),
/// 0 when not (it is dropped).
fn tube_write(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let sent = sim.tubes.write(a.int(0)?, a.bytes(1)?)?;
    Ok(vec![Value::Int(i64::from(sent))])
}

/// `sim.tubeRead(tubeHandle)`: the oldest packet waiting, or nil.
fn tube_read(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    Ok(vec![sim.tubes.read(a.int(0)?)?.map_or(Value::Nil, Value::Bytes)])
}

/// `sim.tubeStatus(tubeHandle)`: status (-1 no such tube, 0 waiting for the other
/// end, 1 connected), packets to read here, packets written here the other end has not
/// read.
fn tube_status(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let count = |n: usize| Value::Int(i64::try_from(n).unwrap_or(i64::MAX));
    Ok(match sim.tubes.status(a.int(0)?) {
        None => vec![Value::Int(-1), Value::Int(0), Value::Int(0)],
        Some(s) => vec![
            Value::Int(i64::from(s.connected)),
            count(s.to_read),
            count(s.unread_by_peer),
        ],
    })
}

/// `sim.tubeClose(tubeHandle)`.
fn tube_close(sim: &mut Sim, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    sim.tubes.close(a.int(0)?)?;
    Ok(Vec::new())
}
