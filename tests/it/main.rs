//! rtbake's integration tests, one binary (one link after a library change) with a module per area.
//!
//! External inputs follow one rule (`support::external`): the golden SMAA/MLAA textures and consumer files
//! (`../shared/reference` or `$RTBAKE_REFERENCE_DIR`) and the physical data tables (`../shared/data` or
//! `$RTBAKE_DATA_DIR`) are optional on a plain clone — a test that needs a missing one says so on stderr (even
//! without `--nocapture`) and checks only what needs nothing external — and `RTBAKE_REQUIRE_REFERENCE=1` (CI) turns
//! every such skip into a failure.

mod support;

mod aa_cli;
mod aa_golden;
mod architecture;
mod bake_cli;
mod bake_dir_concurrency;
mod baked_conformance;
mod budget_refusals;
mod burley_bake;
mod burley_cli;
mod cli_input_errors;
mod cli_outputs_and_help;
mod consumers_bevy;
mod consumers_csv;
mod consumers_dds;
mod consumers_exr;
mod consumers_json_errors;
mod consumers_output_shapes;
mod consumers_pictures;
mod consumers_png;
mod consumers_separable_sss;
mod consumers_sources;
mod consumers_zstd;
mod diffusion_cli;
mod diffusion_layered;
mod diffusion_physics;
mod diffusion_profile_floor;
mod evaluate_cli;
mod facial_cli;
mod facial_rig;
mod facial_wrinkles;
mod file_set_outputs;
mod first_hour_cli;
mod fit_layered_cli;
mod fitting_bake;
mod fitting_cli;
mod fitting_determinism;
mod fitting_published;
mod importance_cli;
mod input_validation_cli;
mod manifest_provenance;
mod mcml_spectral_skin;
mod mesh_raster;
mod mesh_scan;
mod output_sets;
mod profile_models_cli;
mod profiles_bake;
mod profiles_cli;
mod readme_commands;
mod report_cli;
mod runtime_cli;
mod runtime_device_limits;
mod runtime_frame_caches;
mod runtime_frame_pool;
mod runtime_gaussian_sss;
mod runtime_golden_textures;
mod runtime_importance_sss;
mod runtime_limits_precheck;
mod runtime_loader;
mod runtime_loader_tables;
mod runtime_mlaa;
mod runtime_pass_profile;
mod runtime_pipeline_cache;
mod runtime_shader_includes;
mod runtime_skin_inputs;
mod runtime_smaa;
mod runtime_sss;
mod runtime_ts_frame;
mod separable_cli;
mod separable_fit;
mod separable_kernel;
mod setup_build;
mod skin_cli;
mod skin_color;
mod skin_color_mc;
mod skin_layers;
mod skin_passes;
mod skin_render;
mod skin_spectral_data;
mod skin_surface_maps;
mod skin_tap_grid;
mod skin_transmittance;
mod skin_ts;
mod smaa_edges;
mod smaa_modes;
mod transmittance_table;
mod transport_cli;
mod transport_gpu;
mod transport_physics;
