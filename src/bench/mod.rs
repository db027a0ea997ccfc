//! Speed against error (SPEC section 8). This version has the error metric;
//! `drape bench` and its report are planned.

pub mod metric;
