//! The protected call scripts run in under the debugger: `call(f, ...)` runs `f` with a
//! message handler that lets the debugger stop at an uncaught error while the failing
//! frame is still on the stack, then raises the error on as if nothing had been there.

use mlua::{Function, Lua, Value as LuaValue};

use super::state::DebugHost;

/// Creates the protected call; the [`DebugHost`] must be in the Lua state's app data.
pub(crate) fn install(lua: &Lua) -> mlua::Result<Function> {
    let on_error = lua.create_function(move |lua, message: LuaValue| {
        if let Some(d) = lua.app_data_ref::<DebugHost>() {
            d.on_error(lua, &message);
        }
        Ok(message)
    })?;
    lua.load(
        r#"
        local xpcall, error, on_error = ...
        local function finish(ok, ...)
            if ok then return ... end
            error((...), 0)
        end
        return function(f, ...) return finish(xpcall(f, on_error, ...)) end
        "#,
    )
    .set_name("@gantry/debug_call.lua")
    .call((
        lua.globals().get::<Function>("xpcall")?,
        lua.globals().get::<Function>("error")?,
        on_error,
    ))
}
