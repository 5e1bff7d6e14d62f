//! rdaylight-glod's integration tests, as one test binary (one link instead of one per file;
//! issue 21). Add a file `foo.rs` here and `mod foo;` below.

mod obb_rotated;
mod robust;
mod shell_filter;
