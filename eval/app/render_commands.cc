// `rovo render`: a dataset of a scene seen by a fisheye rig (render/render.h), with the sensor and timing options.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "eval/app/commands.h"
#include "render/render.h"
#include "render/timing.h"

namespace rovo {
namespace {

void ParseShard(const std::string& text, int* index, int* count) {
  const size_t slash = text.find('/');
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    *index = std::stoi(text.substr(0, slash));
    *count = std::stoi(text.substr(slash + 1));
  } catch (const std::exception&) {
    throw std::invalid_argument("--shard '" + text + "': expected I/N, e.g. 0/4");
  }
}

// The sensor options of `rovo render` (render/sensor.h); applied by Resolve() on top of --sensor.
struct SensorArgs {
  std::string profile = "off";
  double exposure_ms = 0, gain = 0, ae_target = 0, sensitivity = 0, spread = 0, full_well = 0, read_noise = 0,
         dark_current = 0;
  std::string auto_exposure, shot_noise, response;
  int adc_bits = 0;
  bool grayscale = false;
  float removed_noise = 0;
  CLI::Option *o_exposure = nullptr, *o_gain = nullptr, *o_target = nullptr, *o_sensitivity = nullptr,
              *o_spread = nullptr, *o_full_well = nullptr, *o_read = nullptr, *o_dark = nullptr, *o_ae = nullptr,
              *o_shot = nullptr, *o_response = nullptr, *o_bits = nullptr, *o_gray = nullptr, *o_noise = nullptr,
              *o_profile = nullptr;

  void Add(CLI::App* cmd) {
    const std::string g = "Sensor model (render/README.md; off by default: the scene's exposure and sRGB)";
    o_profile =
        cmd->add_option("--sensor", profile,
                        "off | ideal (HDR sun, auto-exposure, sRGB response, no noise) | realistic (automotive fisheye "
                        "camera: 12-bit ADC, 10 ke- full well, 3 e- read noise, shot noise, dark current, BT.709 "
                        "response, 5 % per-camera sensitivity spread); exposure.csv records every exposure")
            ->check(CLI::IsMember({"off", "ideal", "realistic"}))
            ->group(g)
            ->capture_default_str();
    auto on_off = CLI::IsMember({"on", "off"});
    o_ae = cmd->add_option("--auto-exposure", auto_exposure,
                           "on | off (default on; off: the fixed --exposure-ms, default 0.1, and --gain, default 1)")
               ->check(on_off)
               ->group(g);
    o_exposure =
        cmd->add_option("--exposure-ms", exposure_ms, "Fixed exposure time in ms (turns auto-exposure off)")->group(g);
    o_gain = cmd->add_option("--gain", gain, "Fixed analogue gain >= 1 (turns auto-exposure off)")->group(g);
    o_target = cmd->add_option("--ae-target", ae_target,
                               "Auto-exposure target: centre-weighted mean signal as a fraction of full scale "
                               "(default 0.18)")
                   ->group(g);
    o_sensitivity =
        cmd->add_option("--sensitivity", sensitivity, "Electrons per ms per unit scene radiance (default 100000)")
            ->group(g);
    o_spread = cmd->add_option("--sensitivity-spread", spread,
                               "Std. dev. of ln(per-camera sensitivity), seeded (ideal 0, realistic 0.05)")
                   ->group(g);
    o_full_well = cmd->add_option("--full-well", full_well, "Full-well capacity, electrons (default 10000)")->group(g);
    o_read = cmd->add_option("--read-noise", read_noise, "Read noise, electrons rms (ideal 0, realistic 3)")->group(g);
    o_dark =
        cmd->add_option("--dark-current", dark_current, "Dark current, electrons/s (ideal 0, realistic 50)")->group(g);
    o_shot = cmd->add_option("--shot-noise", shot_noise, "on | off: Poisson shot noise (ideal off, realistic on)")
                 ->check(on_off)
                 ->group(g);
    o_bits = cmd->add_option("--adc-bits", adc_bits, "ADC bits in [8, 16] (ideal 16, realistic 12)")->group(g);
    o_response = cmd->add_option("--response", response,
                                 "Camera response curve: srgb | bt709 | linear (ideal srgb, realistic bt709)")
                     ->check(CLI::IsMember({"srgb", "bt709", "linear"}))
                     ->group(g);
    o_gray = cmd->add_flag("--grayscale", grayscale, "Grayscale sensor: 1-channel PNG of the luminance")->group(g);
    // Removed: the Gaussian 8-bit noise of earlier versions (hidden; fails with a pointer to --sensor).
    o_noise = cmd->add_option("--noise", removed_noise, "")->group("");
  }

  SensorSettings Resolve() const {
    if (o_noise->count() > 0)
      throw std::invalid_argument(
          "--noise was removed: the Gaussian noise in 8-bit units is replaced by the physical sensor model; use "
          "--sensor realistic (shot, read and dark-current noise), or e.g. --sensor ideal --shot-noise on "
          "--read-noise 3 (render/README.md, datasets/FORMAT.md section Sensor)");
    SensorOverrides o;
    if (o_exposure->count()) o.exposure_ms = exposure_ms;
    if (o_gain->count()) o.gain = gain;
    if (o_target->count()) o.ae_target = ae_target;
    if (o_sensitivity->count()) o.sensitivity = sensitivity;
    if (o_spread->count()) o.sensitivity_spread = spread;
    if (o_full_well->count()) o.full_well = full_well;
    if (o_read->count()) o.read_noise = read_noise;
    if (o_dark->count()) o.dark_current = dark_current;
    if (o_ae->count()) o.auto_exposure = auto_exposure == "on";
    if (o_shot->count()) o.shot_noise = shot_noise == "on";
    if (o_bits->count()) o.adc_bits = adc_bits;
    if (o_response->count()) o.response = response;
    if (o_gray->count()) o.grayscale = grayscale;
    return MakeSensorSettings(profile, o);
  }
};

// The lens options of `rovo render` (render/optics.h); applied by Resolve() on top of --optics.
struct OpticsArgs {
  std::string profile = "off";
  OpticsOverrides overrides;
  std::vector<double> lateral_ca;
  CLI::Option* o_profile = nullptr;

  void Add(CLI::App* cmd) {
    const std::string g = "Lens optics (render/optics.h, datasets/FORMAT.md section Optics; off by default)";
    const OpticsSettings r = OpticsProfile("realistic");
    char d[512];
    std::snprintf(d, sizeof(d),
                  "off | realistic (a 220-degree fisheye: Gaussian PSF of MTF50 %g cycles/px on the axis, %g at the "
                  "rim; cos^4(%g theta) fall-off times %g relative illumination at the rim; lateral colour %+g/%+g; "
                  "%g veiling glare); needs the sensor model",
                  r.mtf50_centre, r.mtf50_rim, r.falloff_angle_scale, r.rim_illumination, r.lateral_ca_red,
                  r.lateral_ca_blue, r.veiling_glare);
    o_profile = cmd->add_option("--optics", profile, d)->check(CLI::IsMember({"off", "realistic"}))->group(g);
    OpticsOverrides& o = overrides;
    cmd->add_option("--mtf50-centre", o.mtf50_centre, "MTF50 on the optical axis, cycles/pixel (0: no blur)")->group(g);
    cmd->add_option("--mtf50-rim", o.mtf50_rim, "MTF50 at the edge of the field of view, cycles/pixel")->group(g);
    cmd->add_option("--mtf50-spread", o.mtf50_spread, "Std. dev. of ln(per-camera MTF50 factor), seeded")->group(g);
    cmd->add_option("--falloff-angle-scale", o.falloff_angle_scale, "k of the natural fall-off cos^4(k theta)")
        ->group(g);
    cmd->add_option("--rim-illumination", o.rim_illumination,
                    "Relative illumination at the edge of the field of view besides cos^4, (0, 1]")
        ->group(g);
    cmd->add_option("--lateral-ca", lateral_ca, "Red,blue magnification minus 1 relative to green, e.g. 0.002,-0.002")
        ->delimiter(',')
        ->expected(2)
        ->group(g);
    cmd->add_option("--veiling-glare", o.veiling_glare, "Fraction of the mean image irradiance added to every pixel")
        ->group(g);
  }
  OpticsSettings Resolve() {
    if (lateral_ca.size() == 2) {
      overrides.lateral_ca_red = lateral_ca[0];
      overrides.lateral_ca_blue = lateral_ca[1];
    }
    return MakeOpticsSettings(profile, overrides);
  }
};

// `--realistic`: the realistic sensor and timing (RealisticTiming) where no option of the command
// line sets them.
void ApplyRealisticProfile(const CLI::App& cmd, SensorArgs* sensor, OpticsArgs* optics, TimingSettings* timing) {
  const TimingSettings realistic = RealisticTiming();
  if (sensor->o_profile->count() == 0) sensor->profile = "realistic";
  if (optics->o_profile->count() == 0) optics->profile = "realistic";
  if (cmd.count("--shutter-ms") == 0 && cmd.count("--motion-blur") == 0)
    timing->shutter_from_sensor = realistic.shutter_from_sensor;
  if (cmd.count("--rolling-shutter-ms") == 0) timing->rolling_shutter_ms = realistic.rolling_shutter_ms;
  if (cmd.count("--trigger-offset-ms") == 0 && cmd.count("--trigger-offsets-ms") == 0)
    timing->trigger_offset_std_ms = realistic.trigger_offset_std_ms;
}

// The timing options of `rovo render` (render/timing.h).
void AddTimingOptions(CLI::App* cmd, TimingSettings* timing) {
  const std::string g = "Timing (datasets/FORMAT.md, section Timing; all off by default)";
  TimingSettings& t = *timing;
  cmd->add_option("--shutter-ms", t.shutter_ms,
                  "Motion blur over a fixed exposure interval of this many ms, centred on each row's time "
                  "(default spp " +
                      std::to_string(kDefaultBlurSpp) + " when blurring)")
      ->group(g);
  cmd->add_flag("--motion-blur", t.shutter_from_sensor,
                "Motion blur over the sensor model's exposure time of each frame and camera (exposure.csv; default "
                "spp " +
                    std::to_string(kDefaultBlurSpp) + " when some exposure reaches " +
                    std::to_string(kBlurSppMinExposureMs).substr(0, 3) + " ms, else " + std::to_string(kDefaultSpp) +
                    ")")
      ->group(g);
  cmd->add_option("--rolling-shutter-ms", t.rolling_shutter_ms,
                  "Rolling shutter: readout time of the whole image in ms, top row first")
      ->group(g);
  cmd->add_option("--trigger-offset-ms", t.trigger_offset_std_ms,
                  "Per-camera trigger offsets: standard deviation in ms of a seeded normal draw (--seed)")
      ->group(g);
  cmd->add_option("--trigger-offsets-ms", t.trigger_offset_ms,
                  "Per-camera trigger offsets in ms, one per camera in rig order, comma-separated")
      ->delimiter(',')
      ->group(g);
}

// The IMU options of `rovo render` (datasets/imu_model.h); each needs --imu.
struct ImuArgs {
  bool on = false;
  double rate_hz = 200.0;
  std::string noise = "adis16448";
  double gyro_density = 0, gyro_walk = 0, accel_density = 0, accel_walk = 0, offset_ms = 0;
  std::vector<double> gyro_bias, accel_bias;
  std::vector<CLI::Option*> options;  // every option but --imu

  void Add(CLI::App* cmd) {
    const std::string g = "IMU (datasets/FORMAT.md, section IMU; off by default)";
    cmd->add_flag("--imu", on,
                  "Also write an IMU on the rig (imu/data.csv, exact.csv, bias.csv), sampled from the continuous-time "
                  "ground truth, mounted at the rig's imu_from_rig (the presets' mount when the rig has none)")
        ->group(g);
    auto add = [&](const std::string& name, auto* value, const std::string& help) {
      options.push_back(cmd->add_option(name, *value, help)->group(g));
      return options.back();
    };
    add("--imu-rate", &rate_hz, "IMU samples per second (default 200)");
    add("--imu-noise", &noise,
        "Noise profile: adis16448 (default; the EuRoC MAV ADIS16448 values) or none (exact measurements)");
    add("--imu-gyro-noise-density", &gyro_density, "Gyroscope white noise density, rad/s/sqrt(Hz) (over the profile)");
    add("--imu-gyro-random-walk", &gyro_walk, "Gyroscope bias random walk, rad/s^2/sqrt(Hz) (over the profile)");
    add("--imu-accel-noise-density", &accel_density,
        "Accelerometer white noise density, m/s^2/sqrt(Hz) (over the profile)");
    add("--imu-accel-random-walk", &accel_walk, "Accelerometer bias random walk, m/s^3/sqrt(Hz) (over the profile)");
    add("--imu-gyro-bias", &gyro_bias, "Initial gyroscope bias x,y,z in rad/s (default: drawn from --seed)")
        ->delimiter(',')
        ->expected(3);
    add("--imu-accel-bias", &accel_bias, "Initial accelerometer bias x,y,z in m/s^2 (default: drawn from --seed)")
        ->delimiter(',')
        ->expected(3);
    add("--imu-time-offset-ms", &offset_ms,
        "IMU clock minus camera clock in ms: t_imu = t_cam + offset (Kalibr's timeshift_cam_imu; default 0)");
  }

  // The settings; throws std::invalid_argument for an IMU option without --imu or a bad value.
  void Resolve(RenderOptions* options) const {
    for (const CLI::Option* o : this->options) {
      if (o->count() && !on) throw std::invalid_argument(o->get_name() + ": needs --imu");
    }
    options->imu = on;
    ImuSettings& s = options->imu_settings;
    s.rate_hz = rate_hz;
    s.noise_profile = noise;
    auto set = [&](const char* name, double value, std::optional<double>* field) {
      for (const CLI::Option* o : this->options)
        if (o->get_name() == name && o->count()) *field = value;
    };
    set("--imu-gyro-noise-density", gyro_density, &s.gyroscope_noise_density);
    set("--imu-gyro-random-walk", gyro_walk, &s.gyroscope_random_walk);
    set("--imu-accel-noise-density", accel_density, &s.accelerometer_noise_density);
    set("--imu-accel-random-walk", accel_walk, &s.accelerometer_random_walk);
    if (gyro_bias.size() == 3) s.gyroscope_initial_bias = Eigen::Vector3d(gyro_bias[0], gyro_bias[1], gyro_bias[2]);
    if (accel_bias.size() == 3)
      s.accelerometer_initial_bias = Eigen::Vector3d(accel_bias[0], accel_bias[1], accel_bias[2]);
    s.time_offset_s = offset_ms / 1000.0;
    if (on) s.Check();
  }
};

// The samples per pixel of `rovo render`: --spp and adaptive sampling (render/tracer.h, AdaptiveSampling).
void AddSamplingOptions(CLI::App* cmd, RenderOptions* options) {
  cmd->add_option("--spp", options->spp,
                  "Samples per pixel (default " + std::to_string(kDefaultSpp) + ", measured; 1 = pixel centres)");
  cmd->add_option("--adaptive", options->adaptive,
                  "Adaptive sampling: a pixel takes " + std::to_string(kDefaultSpp) +
                      " samples and doubles them while the means of their two halves differ by more than "
                      "--adaptive-threshold, up to --spp; auto = on when motion blur takes the default spp (" +
                      std::to_string(kDefaultBlurSpp) + ")")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  cmd->add_option("--adaptive-threshold", options->adaptive_threshold_codes,
                  "Difference of the means of a pixel's two halves of samples, in 8-bit codes of the output, above "
                  "which it takes more (default " +
                      std::to_string(kAdaptiveThresholdCodes).substr(0, 3) + "; 0 = the default)")
      ->check(CLI::Range(0.0, 255.0));
}

void AddRenderCommand(CLI::App& root) {
  struct Args {
    RenderOptions options;
    std::string frames, shard;
    SensorArgs sensor;
    OpticsArgs optics;
    ImuArgs imu;
    bool realistic = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = root.add_subcommand(
      "render",
      "Render a dataset (datasets/FORMAT.md) of a scene seen by a fisheye rig with the Embree tracer: "
      "camN/NNNNNN.png, groundtruth.tum, dataset.json, optional depth/ and masks/ (and exposure.csv with "
      "--sensor, imu/ with --imu). Resumable: rerunning "
      "skips frames whose files all exist.");
  auto* preset =
      cmd->add_option("--preset", args->options.preset, "Scene preset to generate and render (e.g. static_urban)");
  auto* scene = cmd->add_option("--scene", args->options.scene_dir, "Scene folder (scenes/FORMAT.md)");
  preset->excludes(scene);
  cmd->add_flag("--quick", args->options.quick, "The preset's quick form: fewer frames, smaller images");
  cmd->add_option(
      "--rig", args->options.rig,
      "Rig preset (rovo4, omnimvs4, rovo4_real; rovo4_stereo / rovo4_mono: rovo4 plus a forward stereo pair "
      "cam4, cam5 / a forward camera cam4 with 100-degree equidistant lenses, for stereo and monocular systems) "
      "or rig.json; default: the scene folder's rig.json, else the scene's rig_preset, else rovo4 (the rig used "
      "is printed)");
  cmd->add_option("--out", args->options.out_dir, "Output dataset folder")->required();
  cmd->add_option("--frames", args->frames, "Trajectory frame range A:B (B exclusive; default: all)");
  cmd->add_option("--shard", args->shard, "Render only shard I of N (chunks of 8 frames), e.g. 0/4");
  AddSamplingOptions(cmd, &args->options);
  cmd->add_option("--threads", args->options.threads, "Render threads (default: all cores)");
  cmd->add_option("--seed", args->options.seed, "Scene seed (with --preset) and seed of the sensor model's draws")
      ->capture_default_str();
  cmd->add_flag("--depth", args->options.depth, "Also write depth/camN/NNNNNN.exr (ray length in metres)");
  cmd->add_flag("--masks", args->options.masks, "Also write masks/camN/NNNNNN.png (16-bit object ids)");
  cmd->add_option("--scale", args->options.scale,
                  "Image size relative to the rig (same lens); default 1, or the preset's quick scale with --quick");
  cmd->add_option("--vignetting", args->options.vignetting, "Vignetting strength in [0, 1] (default 0)");
  args->sensor.Add(cmd);
  args->optics.Add(cmd);
  AddTimingOptions(cmd, &args->options.timing);
  {
    const TimingSettings realistic = RealisticTiming();
    char values[160];
    std::snprintf(values, sizeof(values), "--rolling-shutter-ms %g --trigger-offset-ms %g",
                  realistic.rolling_shutter_ms, realistic.trigger_offset_std_ms);
    cmd->add_flag("--realistic", args->realistic,
                  std::string("The realistic profile of an automotive fisheye camera (render/README.md): --sensor "
                              "realistic --optics realistic --motion-blur ") +
                      values + "; options given beside it override these");
  }
  args->imu.Add(cmd);
  cmd->add_flag("--quiet", args->options.quiet, "No progress output");
  cmd->callback([args, cmd] {
    RenderOptions options = args->options;
    if (!args->frames.empty()) ParseFrameRange(args->frames, &options.frame_begin, &options.frame_end);
    if (!args->shard.empty()) ParseShard(args->shard, &options.shard_index, &options.shard_count);
    if (args->realistic) ApplyRealisticProfile(*cmd, &args->sensor, &args->optics, &options.timing);
    options.sensor = args->sensor.Resolve();
    options.optics = args->optics.Resolve();
    args->imu.Resolve(&options);
    const RenderSummary s = RenderDataset(options);
    std::printf("rendered %d frames, skipped %d complete, %d in this shard, %.1f s", s.frames_rendered,
                s.frames_skipped, s.frames_total, s.seconds);
    if (s.frames_rendered > 0)
      std::printf(" (%.2f CPU-s per frame, without the scene's build)", s.frames_cpu_seconds / s.frames_rendered);
    std::printf("\n%s\n", s.rig.c_str());
  });
}

}  // namespace

void AddRenderCommands(CommandTree& tree) {
  // `rovo render`.
  AddRenderCommand(*tree.root);
}

}  // namespace rovo
