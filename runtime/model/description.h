// A machine description: the values of one `models/**/<machine>.yaml`, validated and in SI units.
//
// This is the immutable "model" half of the pinocchio split (STYLE.md): loaded once, shared by
// the code generator, the interpreted reference kinematics, the plant and the CLI. Field-by-field
// documentation (unit, default, meaning, seed equation) is in models/README.md.
//
// Planar conventions (wheel-loader seed §3.1, Fig. 3): frame M sits at the boom foot pin, x
// forward and horizontal in the vehicle, z up. Every planar angle is measured from M's x axis
// towards its z axis, so a positive angle raises a link. Link k's body frame has its origin at
// the link's pivot and its x axis along the link line (pivot to the next pin, or to the bucket
// tip B for the last link); its angle in M is φ_k (Eq. 1).
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "runtime/core/diagnostics.h"

namespace autoshovel::model {

enum class MachineKind { kWheelLoader, kExcavator };
enum class DriveKind { kElectric, kDiesel };
enum class ActuatorKind { kCylinder, kMotor };

/// A material of the yard (models/materials/*.yaml).
struct Material {
  std::string name;
  std::string source_file;
  double density = 0;               ///< bulk density in the pile [kg/m³]
  double friction_angle = 0;        ///< internal friction angle φ [rad]
  double interface_friction_angle;  ///< soil–steel friction angle δ [rad]
  double cohesion = 0;              ///< c [Pa]
  double angle_of_repose = 0;       ///< [rad]
  bool difficult = false;           ///< in the set 𝒴 of Alg. 3 (scooped with "Stairway")
  double reflectivity = 0;          ///< LiDAR reflectivity [0, 1]
};

/// Where a cylinder end is pinned: a point in a body frame.
struct Mount {
  /// "chassis" (frame M), a link name, or "rocker" (the bell crank of the driven link's
  /// four-bar). A cylinder may connect any two of them (issue 39): a Z-bar's tilt cylinder runs
  /// from the chassis to the rocker, so its length depends on the boom and the bucket joint.
  std::string body;
  Eigen::Vector2d point;  ///< [x, z] in that body's frame [m]
};

/// A four-bar between a link's parent and the link, driving the link through a rocker
/// (loader Z-bar, excavator bucket linkage). The rocker pivots on the parent link at
/// `rocker_pivot`; a coupler of length `coupler_length` joins the rocker's far end F, at
/// `rocker_length` from its pivot, to the child's `child_coupler_point` G. The rocker frame has
/// its origin at the rocker pivot and its x axis towards F; a cylinder may be pinned to it
/// (body "rocker").
struct FourBarLinkage {
  Eigen::Vector2d rocker_pivot = Eigen::Vector2d::Zero();         ///< parent link frame [m]
  double rocker_length = 0;                                       ///< pivot to F [m]
  Eigen::Vector2d child_coupler_point = Eigen::Vector2d::Zero();  ///< child link frame [m]
  double coupler_length = 0;                                      ///< F to G [m]
  /// Which of the two closures: +1 puts F to the left of the line from the rocker pivot to G
  /// (counter-clockwise in the x–z plane), -1 to the right.
  int assembly_branch = 1;
  // Inertial properties of the passive bodies (optional, zero when not given). The rocker and
  // the coupler move with the closure of the chain; their kinetic and potential energy enter
  // the plant's Lagrangian through it (codegen/symbolic_model.cc).
  double rocker_mass = 0;                                           ///< [kg]
  Eigen::Vector2d rocker_center_of_mass = Eigen::Vector2d::Zero();  ///< rocker frame [m]
  double rocker_inertia = 0;   ///< about its centre of mass [kg·m²]
  double coupler_mass = 0;     ///< [kg], centre of mass midway between F and G
  double coupler_inertia = 0;  ///< about its centre of mass [kg·m²]
};

struct Link {
  std::string name;
  double length = 0;      ///< l_k, pivot to next pin or to tip B [m] (Eq. 2)
  double imu_offset = 0;  ///< α_k, IMU mounting offset [rad] (Eq. 1)
  double joint_min = 0;   ///< joint limit [rad]: φ_1 for the first link, φ_k − φ_{k−1} after
  double joint_max = 0;
  double mass = 0;                                           ///< [kg]
  Eigen::Vector2d center_of_mass = Eigen::Vector2d::Zero();  ///< in the link frame [m]
  double inertia = 0;                     ///< about the centre of mass, planar [kg·m²]
  double viscous_friction = 0;            ///< at the joint [N·m·s/rad]
  std::optional<FourBarLinkage> linkage;  ///< present when an actuator drives it through one
};

/// Swing joint of an excavator (vertical axis through the base origin).
struct Swing {
  double joint_min = 0;         ///< [rad]
  double joint_max = 0;         ///< [rad]
  double inertia = 0;           ///< upper structure without the arm, about the swing axis [kg·m²]
  double viscous_friction = 0;  ///< [N·m·s/rad]
};

/// One point of a valve's opening curve: opening (fraction of the full spool opening) at a duty
/// (fraction of the full command), both in [0, 1].
struct OpeningPoint {
  double duty = 0;
  double opening = 0;
};

/// The valve chain (docs/simulation.md "Valve chain"): command u → pure delay τ_p + τ_d → pilot
/// lag T_p → opening law of the direction → spool lag τ_s → orifice Q = K_v·x_s·√Δp.
struct Valve {
  double dead_zone = 0;            ///< fraction of full command ignored around zero [-]
  double transport_delay = 0;      ///< τ_d, pilot to spool start [s] (command to spool start
                                   ///< when there is no pilot stage)
  double pilot_delay = 0;          ///< τ_p, command to pilot pressure start [s]
  double pilot_time_constant = 0;  ///< T_p, first-order pilot lag [s]; 0: no pilot stage
  /// Opening against duty per direction (extend: u > 0, retract: u < 0): piecewise linear
  /// through the points, 0 below the first, the last opening above the last. Empty: the dead
  /// zone and the linear law (ApplyDeadZone) for that direction.
  std::vector<OpeningPoint> opening_curve_extend;
  std::vector<OpeningPoint> opening_curve_retract;
  double spool_time_constant = 0;  ///< τ_s, first-order spool lag [s]
  double flow_gain = 0;            ///< K_v in Q = K_v·x_s·sqrt(Δp) [m³/(s·√Pa)]
  double rated_flow = 0;           ///< as given: flow at full spool and rated drop [m³/s]
  double rated_pressure_drop = 0;  ///< [Pa]
};

struct Actuator {
  std::string name;
  ActuatorKind kind = ActuatorKind::kCylinder;
  std::string joint;  ///< the link (or "swing") it drives
  int count = 1;      ///< identical actuators acting in parallel
  // Cylinder (kind == kCylinder):
  double bore = 0;              ///< piston diameter [m]
  double rod = 0;               ///< rod diameter [m]
  double stroke = 0;            ///< [m]
  double retracted_length = 0;  ///< pin-to-pin length fully retracted [m]
  Mount base_mount;             ///< the barrel end
  Mount rod_mount;              ///< the rod end
  double dead_volume = 0;       ///< per chamber, hoses included [m³]
  // Inertial properties of each cylinder's two bodies (optional, zero when not given): the
  // barrel turns about the base pin, the rod about the rod pin, both along the pin-to-pin line.
  double barrel_mass = 0;    ///< [kg], one cylinder
  double barrel_center = 0;  ///< distance of its centre of mass from the base pin [m]
  double rod_mass = 0;       ///< [kg], piston and rod of one cylinder
  double rod_center = 0;     ///< distance of its centre of mass from the rod pin [m]
  // Motor (kind == kMotor):
  double displacement = 0;  ///< at the joint, gearing included [m³/rad]
  double line_volume = 0;   ///< per side [m³]
  Valve valve;
  double relief_pressure = 0;  ///< [Pa]
};

struct Hydraulics {
  double pump_pressure = 0;    ///< supply pressure [Pa]
  double tank_pressure = 0;    ///< return pressure [Pa]
  double bulk_modulus = 0;     ///< effective oil bulk modulus β [Pa]
  double pump_efficiency = 0;  ///< hydraulic energy accounting η [-]
  /// The pump's largest delivery, displacement × shaft speed [m³/s]; 0: unlimited (the valves'
  /// rated flows are the only limit, as before the key existed).
  double pump_max_flow = 0;
  std::vector<Actuator> actuators;
};

struct Chassis {
  double operating_mass = 0;  ///< [kg]
  // Wheel loader:
  double hinge_to_front_axle = 0;       ///< [m]
  double hinge_to_rear_axle = 0;        ///< [m]
  double track_width = 0;               ///< [m]
  double wheel_radius = 0;              ///< [m]
  double front_axle_load_fraction = 0;  ///< of the operating mass, unloaded [-]
  double max_articulation = 0;          ///< [rad]
  double max_articulation_rate = 0;     ///< [rad/s]
  double rolling_resistance = 0;        ///< coefficient [-]
  double traction_coefficient = 0;      ///< μ [-]
  double max_speed = 0;                 ///< [m/s]
  // Excavator:
  double track_gauge = 0;       ///< [m]
  double track_length = 0;      ///< [m]
  double track_shoe_width = 0;  ///< [m]
};

struct ElectricMotor {
  double max_torque = 0;  ///< at the motor shaft [N·m]
  double max_power = 0;   ///< [W]
  double gear_ratio = 0;  ///< motor to wheel [-]
  double efficiency = 0;  ///< drive train, battery to wheel [-]
};

struct DieselEngine {
  double rated_power = 0;             ///< [W]
  double max_torque = 0;              ///< [N·m]
  double rated_speed = 0;             ///< [rad/s]
  double throttle_time_constant = 0;  ///< [s]
  double gear_ratio = 0;              ///< engine to wheel, lowest working gear [-]
  double efficiency = 0;              ///< fuel energy not counted: engine shaft to wheel [-]
};

struct Bucket {
  double width = 0;                      ///< [m]
  double rated_capacity = 0;             ///< heaped, SAE J742 [m³]
  double rated_load = 0;                 ///< [kg]
  std::vector<Eigen::Vector2d> profile;  ///< cross-section polygon, bucket frame [m], tip first
  std::string design_material;           ///< material the bucket is sized for
};

struct Pose3 {
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();  ///< [m]
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();  ///< roll, pitch, yaw [rad]
};

struct Camera {
  int width_px = 0;
  int height_px = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< [px]
  Pose3 pose;                             ///< in the vehicle frame
};

struct Lidar {
  std::string name;
  std::string model;             ///< "spinning" | "non_repetitive"
  int lines = 0;                 ///< spinning only
  double horizontal_fov = 0;     ///< [rad]
  double vertical_fov = 0;       ///< [rad]
  double rate = 0;               ///< frames per second [Hz]
  double points_per_second = 0;  ///< [1/s]
  double max_range = 0;          ///< [m]
  double range_noise = 0;        ///< 1σ at 10 m [m]
  Pose3 pose;
};

struct Imu {
  std::string name;
  std::string body;        ///< "chassis" or a link name
  double angle_noise = 0;  ///< 1σ [rad]
  double bias = 0;         ///< constant bias [rad]
};

struct Sensors {
  Camera camera;
  std::vector<Lidar> lidars;
  std::vector<Imu> imus;
};

/// A validated machine description. Every field is SI.
struct MachineDescription {
  std::string name;
  MachineKind kind = MachineKind::kWheelLoader;
  DriveKind drive = DriveKind::kDiesel;
  std::string source_file;             ///< as given to the loader
  std::string sha256;                  ///< of the file's bytes
  std::string notes;                   ///< provenance, free text
  std::vector<std::string> estimated;  ///< key paths whose values are estimates
  std::vector<std::string> overlays;   ///< overlay files applied on top, in order
  /// Overlay values that generated code compiles in (a valve's spool time constant and rated
  /// flow), as "overlay file: key path": code generated from the base file would ignore them,
  /// so a machine with any runs the interpreted model (runtime/machines/machine_code.h).
  std::vector<std::string> overlay_code_keys;

  Chassis chassis;
  std::optional<ElectricMotor> electric_motor;
  std::optional<DieselEngine> diesel_engine;
  Eigen::Vector2d arm_pivot = Eigen::Vector2d::Zero();  ///< M origin in the vehicle frame [x, z]
  std::vector<Link> links;     ///< boom, bucket (loader); boom, stick, bucket (excavator)
  std::optional<Swing> swing;  ///< excavators
  Hydraulics hydraulics;
  Bucket bucket;
  Sensors sensors;
  std::vector<Material> materials;  ///< every material of the folders searched
  /// The material folders searched, in order (LoadOptions; the unknown-material error names them).
  std::vector<std::string> materials_searched;
  /// Plausibility warnings (runtime/model/plausibility.h): values outside physical ranges that
  /// still load, each naming the likely unit mistake. Also written once to standard error.
  std::vector<core::Diagnostic> warnings;

  /// Where each value came from, by key path, for errors found after loading.
  std::map<std::string, core::SourceLocation> locations;

  std::size_t num_links() const { return links.size(); }
  /// Joints in plant order: one per link, then the swing if any.
  std::size_t num_joints() const { return links.size() + (swing ? 1 : 0); }
  /// Index of a link by name, or -1.
  int LinkIndex(const std::string& link_name) const;
  /// Index of the actuator driving joint `joint_index`, or -1.
  int ActuatorOfJoint(std::size_t joint_index) const;
  const Material* FindMaterial(const std::string& material_name) const;
  /// The LiDAR named `lidar_name` in sensors.lidars, or null.
  const Lidar* FindLidar(std::string_view lidar_name) const;
  /// Location recorded for `key_path`, else the file itself.
  core::SourceLocation LocationOf(const std::string& key_path) const;
};

struct LoadOptions {
  /// Where material files are found: this folder alone. Empty: `<description dir>/../materials`,
  /// then `<models_dir>/materials`, a name found in the first folder that has it (see
  /// MaterialFolders). `autoshovel --materials DIR` and `--models DIR` set the process-wide
  /// defaults (SetDefaultMaterialFolders) that apply when these fields are empty.
  std::string materials_dir;
  /// The models/ folder whose `materials/` is searched after the description's own.
  std::string models_dir;
  /// Overlays applied in order on top of the description before it is validated: files
  /// written by identification (`autoshovel calibrate arm` …) holding identified values. An
  /// overlay names its machine and the SHA-256 of the description it was identified against;
  /// both must match. Schema (every value optional, units as in the description):
  /// `machine`, `base_sha256`, `arm.links[]{name, length, imu_offset_deg}`,
  /// `hydraulics.actuators[]{name, dead_zone, transport_delay, spool_time_constant,
  /// rated_flow_lpm, pilot_delay, pilot_time_constant, opening_curve_extend,
  /// opening_curve_retract}`, `sensors.camera.pose{xyz, rpy_deg}`, `sensors.lidars[]{name, pose}`.
  std::vector<std::string> overlays;
};

/// Loads and validates a machine description. Throws core::InputError listing every problem
/// (`file:line:column: key.path: message`); never returns a partly read description.
MachineDescription LoadMachineDescription(const std::string& path, const LoadOptions& options = {});

/// Process-wide defaults for LoadOptions::materials_dir and models_dir, set once by the command
/// line (`--materials`, `--models`) so that every command that loads a description honours them.
void SetDefaultMaterialFolders(const std::string& materials_dir, const std::string& models_dir);

/// The material folders searched for a description at `path`, in order, without duplicates.
std::vector<std::string> MaterialFolders(const std::string& path, const LoadOptions& options);

/// Loads one material file. Throws core::InputError.
Material LoadMaterial(const std::string& path);

/// All materials of a directory, sorted by name. Throws core::InputError.
std::vector<Material> LoadMaterials(const std::string& directory);

/// Machine descriptions under a models/ folder: every `*.yaml` except in materials/ and
/// scenarios/ and the trained models' provenance files `*.meta.yaml`, sorted.
std::vector<std::string> FindMachineDescriptions(const std::string& models_dir);

/// A machine given by name (searched under `models_dir`) or by path to its description.
/// Throws std::runtime_error listing the known machines when nothing matches.
std::string ResolveMachineDescription(const std::string& name_or_path,
                                      const std::string& models_dir);

const char* ToString(MachineKind kind);
const char* ToString(DriveKind drive);

}  // namespace autoshovel::model
