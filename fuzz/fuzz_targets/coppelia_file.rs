//! CoppeliaSim scene/model reader: any bytes read or fail with an error, never panic,
//! and every file that reads keeps the reader's documented guarantees (mesh indices in
//! range, whole triangles, caps). Seeds in `fuzz/seeds/coppelia_file/` are small
//! synthetic files written by the crate's tests (`write_fuzz_seeds`), so the fuzzer
//! starts past the header and the Huffman layer.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(file) = gantry_coppelia_file::read(data) {
        if let Err(broken) = file.check_guarantees() {
            panic!("reader guarantee broken: {broken}");
        }
    }
});
