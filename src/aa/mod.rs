//! Antialiasing lookup textures (thesis ch. 9 and 10; `specs/smaa-mlaa.md`): pure computation, no I/O.
