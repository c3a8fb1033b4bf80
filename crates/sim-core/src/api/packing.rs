//! Packing numbers and tables into byte strings: `sim.packFloatTable`,
//! `sim.unpackFloatTable`, the double, int32, uint32, uint16 and uint8 variants, and
//! `sim.packTable` / `sim.unpackTable`.
//!
//! Numbers are packed little-endian, as CoppeliaSim does on every platform it runs on
//! (floats as IEEE-754 single precision). Packed data is returned as bytes (a Lua string
//! that is not text, a CBOR byte string for remote clients). Tables are packed as CBOR
//! (`gantry_protocol::cbor`, the codec of the ZMQ remote API) whichever scheme is asked
//! for, and `sim.unpackTable` accepts any CBOR item: it is total and bounded like every
//! decoder of peer data in gantry (a clear error, never a panic, on arbitrary bytes).

use crate::error::SimError;
use gantry_protocol::cbor;

use super::{ApiFn, ApiFunction, Args, CallContext, Cost, Ret};
use crate::Value;
use crate::world::World;

/// The functions this file implements, sorted by name.
pub(super) const FUNCTIONS: &[ApiFunction] = &[
    ApiFunction {
        name: "packDoubleTable",
        call: ApiFn::World(pack_double_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "packFloatTable",
        call: ApiFn::World(pack_float_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "packInt32Table",
        call: ApiFn::World(pack_int32_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "packTable",
        call: ApiFn::World(pack_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "packUInt16Table",
        call: ApiFn::World(pack_uint16_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "packUInt32Table",
        call: ApiFn::World(pack_uint32_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "packUInt8Table",
        call: ApiFn::World(pack_uint8_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackDoubleTable",
        call: ApiFn::World(unpack_double_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackFloatTable",
        call: ApiFn::World(unpack_float_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackInt32Table",
        call: ApiFn::World(unpack_int32_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackTable",
        call: ApiFn::World(unpack_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackUInt16Table",
        call: ApiFn::World(unpack_uint16_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackUInt32Table",
        call: ApiFn::World(unpack_uint32_table),
        cost: Cost::Quick,
    },
    ApiFunction {
        name: "unpackUInt8Table",
        call: ApiFn::World(unpack_uint8_table),
        cost: Cost::Quick,
    },
];

/// `sim.packTable`'s packing schemes: 0 is CoppeliaSim's own format, 1 CBOR. gantry
/// writes CBOR for both.
const SCHEMES: std::ops::RangeInclusive<i64> = 0..=1;

/// An optional non-negative integer argument (start index, count, byte offset).
fn opt_index(a: &Args<'_>, i: usize, what: &str) -> Result<usize, SimError> {
    let v = a.opt_int(i, 0)?;
    usize::try_from(v)
        .map_err(|_| SimError::bad_argument(format!("argument {} ({what}): must be 0 or more, got {v}", i + 1)))
}

/// The start index and the elements of argument 0 from it, at most `count` of them (0:
/// all the rest), as CoppeliaSim's pack functions select them; a start past the end
/// selects none.
fn selected<'v>(a: &'v Args<'_>) -> Result<(usize, &'v [Value]), SimError> {
    let Value::Array(items) = a.get(0) else {
        return Err(SimError::bad_argument(format!(
            "argument 1: expected a table of numbers, got {}",
            a.get(0).type_name()
        )));
    };
    let start = opt_index(a, 1, "start index")?;
    let count = opt_index(a, 2, "count")?;
    let rest = items.get(start..).unwrap_or(&[]);
    Ok((
        start,
        if count == 0 {
            rest
        } else {
            &rest[..count.min(rest.len())]
        },
    ))
}

/// Packs the selected numbers with `put`, which gets each number and its 1-based index
/// in the table (for error messages).
fn pack_with(a: &Args<'_>, put: impl Fn(&Value, usize, &mut Vec<u8>) -> Result<(), SimError>) -> Result<Ret, SimError> {
    let (start, items) = selected(a)?;
    let mut out = Vec::new();
    for (k, v) in items.iter().enumerate() {
        put(v, start + k + 1, &mut out)?;
    }
    Ok(vec![Value::Bytes(out)])
}

/// Element `index` as a number (any float, NaN and infinities included: they pack).
fn float_item(v: &Value, index: usize) -> Result<f64, SimError> {
    v.as_f64().ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 1: element {index} must be a number, got {}",
            v.type_name()
        ))
    })
}

/// Element `index` as an integer in `T`'s range (an integral float is accepted).
fn int_item<T: TryFrom<i64>>(v: &Value, index: usize, type_name: &str) -> Result<T, SimError> {
    let i = v.as_i64().ok_or_else(|| {
        SimError::bad_argument(format!(
            "argument 1: element {index} must be an integer, got {}",
            match v {
                Value::Float(f) => format!("{f}"),
                other => other.type_name().to_owned(),
            }
        ))
    })?;
    T::try_from(i).map_err(|_| {
        SimError::bad_argument(format!(
            "argument 1: element {index} ({i}) does not fit in a {type_name}"
        ))
    })
}

/// `sim.packFloatTable(numbers, startIndex=0, count=0)` → bytes: little-endian `f32`s.
fn pack_float_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    // Narrowing to single precision is the point of this function.
    pack_with(a, |v, k, out| {
        out.extend_from_slice(&(float_item(v, k)? as f32).to_le_bytes());
        Ok(())
    })
}

/// `sim.packDoubleTable(numbers, startIndex=0, count=0)` → bytes: little-endian `f64`s.
fn pack_double_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    pack_with(a, |v, k, out| {
        out.extend_from_slice(&float_item(v, k)?.to_le_bytes());
        Ok(())
    })
}

/// `sim.packInt32Table(numbers, startIndex=0, count=0)` → bytes: little-endian `i32`s.
fn pack_int32_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    pack_with(a, |v, k, out| {
        out.extend_from_slice(&int_item::<i32>(v, k, "int32")?.to_le_bytes());
        Ok(())
    })
}

/// `sim.packUInt32Table(numbers, startIndex=0, count=0)` → bytes: little-endian `u32`s.
fn pack_uint32_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    pack_with(a, |v, k, out| {
        out.extend_from_slice(&int_item::<u32>(v, k, "uint32")?.to_le_bytes());
        Ok(())
    })
}

/// `sim.packUInt16Table(numbers, startIndex=0, count=0)` → bytes: little-endian `u16`s.
fn pack_uint16_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    pack_with(a, |v, k, out| {
        out.extend_from_slice(&int_item::<u16>(v, k, "uint16")?.to_le_bytes());
        Ok(())
    })
}

/// `sim.packUInt8Table(numbers, startIndex=0, count=0)` → bytes.
fn pack_uint8_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    pack_with(a, |v, k, out| {
        out.push(int_item::<u8>(v, k, "uint8")?);
        Ok(())
    })
}

/// The bytes of argument 0 that hold the values to unpack: from byte
/// `additionalByteOffset + startIndex * size`, at most `count` values (0: as many whole
/// values as remain). Trailing bytes that do not make a whole value are ignored; a start
/// past the end gives no values.
fn unpack_range(a: &Args<'_>, size: usize, with_byte_offset: bool) -> Result<Vec<u8>, SimError> {
    let data = a.bytes(0)?;
    let start = opt_index(a, 1, "start index")?;
    let count = opt_index(a, 2, "count")?;
    let offset = if with_byte_offset {
        opt_index(a, 3, "additional byte offset")?
    } else {
        0
    };
    // Saturating: indices come from scripts, and a huge one just selects nothing.
    let first = start.saturating_mul(size).saturating_add(offset);
    let available = data.len().saturating_sub(first) / size;
    let n = if count == 0 { available } else { count.min(available) };
    Ok(data
        .get(first..first + n * size)
        .map(<[u8]>::to_vec)
        .unwrap_or_default())
}

/// Unpacks fixed-size little-endian values with `read`.
fn unpack_with<const N: usize>(
    a: &Args<'_>,
    with_byte_offset: bool,
    read: impl Fn([u8; N]) -> Value,
) -> Result<Ret, SimError> {
    let bytes = unpack_range(a, N, with_byte_offset)?;
    let values = bytes
        .chunks_exact(N)
        .map(|c| {
            let mut b = [0; N];
            b.copy_from_slice(c);
            read(b)
        })
        .collect();
    Ok(vec![Value::Array(values)])
}

/// `sim.unpackFloatTable(data, startIndex=0, count=0, additionalByteOffset=0)` → numbers.
fn unpack_float_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    // One decoder of packed floats in gantry: the vision sensors' (their packets are
    // packed float tables).
    let bytes = unpack_range(a, 4, true)?;
    Ok(vec![Value::floats(&crate::vision::unpack_floats(&bytes))])
}

/// `sim.unpackDoubleTable(data, startIndex=0, count=0, additionalByteOffset=0)` → numbers.
fn unpack_double_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    unpack_with::<8>(a, true, |b| Value::Float(f64::from_le_bytes(b)))
}

/// `sim.unpackInt32Table(data, startIndex=0, count=0, additionalByteOffset=0)` → integers.
fn unpack_int32_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    unpack_with::<4>(a, true, |b| Value::Int(i64::from(i32::from_le_bytes(b))))
}

/// `sim.unpackUInt32Table(data, startIndex=0, count=0, additionalByteOffset=0)` → integers.
fn unpack_uint32_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    unpack_with::<4>(a, true, |b| Value::Int(i64::from(u32::from_le_bytes(b))))
}

/// `sim.unpackUInt16Table(data, startIndex=0, count=0, additionalByteOffset=0)` → integers.
fn unpack_uint16_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    unpack_with::<2>(a, true, |b| Value::Int(i64::from(u16::from_le_bytes(b))))
}

/// `sim.unpackUInt8Table(data, startIndex=0, count=0)` → integers (CoppeliaSim has no
/// byte offset here: the start index already is one).
fn unpack_uint8_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    unpack_with::<1>(a, false, |b| Value::Int(i64::from(b[0])))
}

/// Checks that `v` nests no deeper than the CBOR decoder accepts and holds no more
/// items, so that whatever `sim.packTable` writes `sim.unpackTable` reads back. Stops
/// as soon as a limit is passed, so the recursion is bounded too.
fn check_packable(v: &Value, depth: usize, items: &mut usize) -> Result<(), SimError> {
    *items += 1;
    if *items > cbor::MAX_ITEMS {
        return Err(SimError::bad_argument(format!(
            "argument 1: the table holds more than {} values",
            cbor::MAX_ITEMS
        )));
    }
    let nested = matches!(v, Value::Array(_) | Value::Map(_));
    if nested && depth >= cbor::MAX_DEPTH {
        return Err(SimError::bad_argument(format!(
            "argument 1: tables nested deeper than {} levels",
            cbor::MAX_DEPTH
        )));
    }
    match v {
        Value::Array(a) => a.iter().try_for_each(|x| check_packable(x, depth + 1, items)),
        Value::Map(m) => m.iter().try_for_each(|(k, x)| {
            check_packable(k, depth + 1, items)?;
            check_packable(x, depth + 1, items)
        }),
        _ => Ok(()),
    }
}

/// `sim.packTable(table, scheme=0)` → bytes: the table (nested tables, nil, booleans,
/// numbers, strings) as CBOR, for either scheme.
fn pack_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let v = a.get(0);
    if !matches!(v, Value::Array(_) | Value::Map(_)) {
        return Err(SimError::bad_argument(format!(
            "argument 1: expected a table, got {}",
            v.type_name()
        )));
    }
    let scheme = a.opt_int(1, 0)?;
    if !SCHEMES.contains(&scheme) {
        return Err(SimError::bad_argument(format!(
            "argument 2 (scheme): expected 0 (CoppeliaSim) or 1 (CBOR), got {scheme}"
        )));
    }
    check_packable(v, 0, &mut 0)?;
    Ok(vec![Value::Bytes(cbor::to_vec(v))])
}

/// `sim.unpackTable(data)` → the table packed by `sim.packTable` (or any CBOR item).
fn unpack_table(_: &mut World, _: &CallContext<'_>, a: &Args<'_>) -> Result<Ret, SimError> {
    let data = a.bytes(0)?;
    let v = cbor::decode(&data).map_err(|e| SimError::bad_argument(format!("argument 1: not a packed table: {e}")))?;
    Ok(vec![v])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_check_stops_at_the_decoder_limit() {
        let mut v = Value::Array(Vec::new());
        for _ in 0..cbor::MAX_DEPTH - 1 {
            v = Value::Array(vec![v]);
        }
        // MAX_DEPTH arrays: exactly what the decoder accepts.
        check_packable(&v, 0, &mut 0).expect("at the limit");
        assert!(cbor::decode(&cbor::to_vec(&v)).is_ok());
        let deeper = Value::Array(vec![v]);
        assert!(check_packable(&deeper, 0, &mut 0).is_err());
        assert!(cbor::decode(&cbor::to_vec(&deeper)).is_err());
    }
}
