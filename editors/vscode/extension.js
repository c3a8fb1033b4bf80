// VS Code extension for gantry's script debugger. gantry itself is the debug adapter:
// `gantry run SCENE --debug[=PORT]` serves the Debug Adapter Protocol over TCP. All this
// extension does is tell VS Code where to connect (type "gantry", request "attach").
'use strict';

const vscode = require('vscode');

const DEFAULT_HOST = '127.0.0.1';
const DEFAULT_PORT = 4711;

/** The port of a configuration (a number, or a string from an input variable). */
function portOf(config) {
    const port = typeof config.port === 'string' ? Number(config.port.trim()) : config.port;
    return Number.isInteger(port) && port > 0 && port < 65536 ? port : undefined;
}

class GantryAdapterFactory {
    createDebugAdapterDescriptor(session) {
        const config = session.configuration;
        const host = typeof config.host === 'string' && config.host.trim() ? config.host.trim() : DEFAULT_HOST;
        const port = portOf(config) ?? DEFAULT_PORT;
        return new vscode.DebugAdapterServer(port, host);
    }
}

class GantryConfigurationProvider {
    // F5 without a launch.json (or with an empty configuration): attach to the default
    // address. Otherwise check the port before VS Code tries to connect.
    resolveDebugConfiguration(folder, config) {
        if (!config.type && !config.request && !config.name) {
            return {
                type: 'gantry',
                request: 'attach',
                name: 'Attach to gantry',
                host: DEFAULT_HOST,
                port: DEFAULT_PORT,
            };
        }
        if (config.port !== undefined && portOf(config) === undefined) {
            return vscode.window
                .showErrorMessage(`gantry: "port" must be a TCP port (1-65535), not ${JSON.stringify(config.port)}`)
                .then(() => undefined);
        }
        return config;
    }
}

function activate(context) {
    context.subscriptions.push(
        vscode.debug.registerDebugAdapterDescriptorFactory('gantry', new GantryAdapterFactory()),
        vscode.debug.registerDebugConfigurationProvider('gantry', new GantryConfigurationProvider()),
    );
}

function deactivate() {}

module.exports = { activate, deactivate };
