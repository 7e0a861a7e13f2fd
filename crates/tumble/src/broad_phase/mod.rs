//! The broad phase: which bodies' bounding boxes overlap.
//! PLACEHOLDER: being written.
