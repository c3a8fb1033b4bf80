//! The ROS 2 message and service types gantry knows, as `.msg`-style text.
//!
//! Fields, their order, types, array sizes and defaults are those of ROS 2 Humble (and
//! unchanged since); comments are left out. Constants are kept because they document
//! the numeric fields (`Range.radiation_type`, `PointField.datatype`), and the codec
//! skips them. Each section starts with `MSG: Type` (or `SRV: Type`, request and
//! response separated by `---`, or `ACTION: Type`, goal, result and feedback separated
//! by `---`); bare nested names are in the same package, and `Header` is
//! `std_msgs/msg/Header`.

/// Message packages: `(package, definitions)`.
pub(crate) const MESSAGES: &[(&str, &str)] = &[
    ("builtin_interfaces", BUILTIN_INTERFACES),
    ("std_msgs", STD_MSGS),
    ("geometry_msgs", GEOMETRY_MSGS),
    ("sensor_msgs", SENSOR_MSGS),
    ("nav_msgs", NAV_MSGS),
    ("rosgraph_msgs", ROSGRAPH_MSGS),
    ("tf2_msgs", TF2_MSGS),
    ("unique_identifier_msgs", UNIQUE_IDENTIFIER_MSGS),
    ("action_msgs", ACTION_MSGS),
];

/// Service packages: `(package, definitions)`.
pub(crate) const SERVICES: &[(&str, &str)] = &[
    ("std_srvs", STD_SRVS),
    ("example_interfaces", EXAMPLE_INTERFACES_SRVS),
    ("action_msgs", ACTION_MSGS_SRVS),
];

/// Action packages: `(package, definitions)`.
pub(crate) const ACTIONS: &[(&str, &str)] = &[("example_interfaces", EXAMPLE_INTERFACES_ACTIONS)];

const BUILTIN_INTERFACES: &str = "
MSG: Time
int32 sec
uint32 nanosec
MSG: Duration
int32 sec
uint32 nanosec
";

const STD_MSGS: &str = "
MSG: Bool
bool data
MSG: Byte
byte data
MSG: Char
char data
MSG: Int8
int8 data
MSG: Int16
int16 data
MSG: Int32
int32 data
MSG: Int64
int64 data
MSG: UInt8
uint8 data
MSG: UInt16
uint16 data
MSG: UInt32
uint32 data
MSG: UInt64
uint64 data
MSG: Float32
float32 data
MSG: Float64
float64 data
MSG: String
string data
MSG: Empty
MSG: Header
builtin_interfaces/Time stamp
string frame_id
MSG: ColorRGBA
float32 r
float32 g
float32 b
float32 a
MSG: MultiArrayDimension
string label
uint32 size
uint32 stride
MSG: MultiArrayLayout
MultiArrayDimension[] dim
uint32 data_offset
MSG: ByteMultiArray
MultiArrayLayout layout
byte[] data
MSG: Float32MultiArray
MultiArrayLayout layout
float32[] data
MSG: Float64MultiArray
MultiArrayLayout layout
float64[] data
MSG: Int8MultiArray
MultiArrayLayout layout
int8[] data
MSG: Int16MultiArray
MultiArrayLayout layout
int16[] data
MSG: Int32MultiArray
MultiArrayLayout layout
int32[] data
MSG: Int64MultiArray
MultiArrayLayout layout
int64[] data
MSG: UInt8MultiArray
MultiArrayLayout layout
uint8[] data
MSG: UInt16MultiArray
MultiArrayLayout layout
uint16[] data
MSG: UInt32MultiArray
MultiArrayLayout layout
uint32[] data
MSG: UInt64MultiArray
MultiArrayLayout layout
uint64[] data
";

const GEOMETRY_MSGS: &str = "
MSG: Point
float64 x
float64 y
float64 z
MSG: Point32
float32 x
float32 y
float32 z
MSG: PointStamped
std_msgs/Header header
Point point
MSG: Vector3
float64 x
float64 y
float64 z
MSG: Vector3Stamped
std_msgs/Header header
Vector3 vector
MSG: Quaternion
float64 x 0
float64 y 0
float64 z 0
float64 w 1
MSG: QuaternionStamped
std_msgs/Header header
Quaternion quaternion
MSG: Pose
Point position
Quaternion orientation
MSG: Pose2D
float64 x
float64 y
float64 theta
MSG: PoseArray
std_msgs/Header header
Pose[] poses
MSG: PoseStamped
std_msgs/Header header
Pose pose
MSG: PoseWithCovariance
Pose pose
float64[36] covariance
MSG: PoseWithCovarianceStamped
std_msgs/Header header
PoseWithCovariance pose
MSG: Twist
Vector3 linear
Vector3 angular
MSG: TwistStamped
std_msgs/Header header
Twist twist
MSG: TwistWithCovariance
Twist twist
float64[36] covariance
MSG: TwistWithCovarianceStamped
std_msgs/Header header
TwistWithCovariance twist
MSG: Transform
Vector3 translation
Quaternion rotation
MSG: TransformStamped
std_msgs/Header header
string child_frame_id
Transform transform
MSG: Wrench
Vector3 force
Vector3 torque
MSG: WrenchStamped
std_msgs/Header header
Wrench wrench
MSG: Accel
Vector3 linear
Vector3 angular
MSG: AccelStamped
std_msgs/Header header
Accel accel
MSG: AccelWithCovariance
Accel accel
float64[36] covariance
MSG: AccelWithCovarianceStamped
std_msgs/Header header
AccelWithCovariance accel
MSG: Inertia
float64 m
geometry_msgs/Vector3 com
float64 ixx
float64 ixy
float64 ixz
float64 iyy
float64 iyz
float64 izz
MSG: InertiaStamped
std_msgs/Header header
Inertia inertia
MSG: Polygon
Point32[] points
MSG: PolygonStamped
std_msgs/Header header
Polygon polygon
";

const SENSOR_MSGS: &str = "
MSG: JointState
std_msgs/Header header
string[] name
float64[] position
float64[] velocity
float64[] effort
MSG: Image
std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
MSG: CompressedImage
std_msgs/Header header
string format
uint8[] data
MSG: RegionOfInterest
uint32 x_offset
uint32 y_offset
uint32 height
uint32 width
bool do_rectify
MSG: CameraInfo
std_msgs/Header header
uint32 height
uint32 width
string distortion_model
float64[] d
float64[9] k
float64[9] r
float64[12] p
uint32 binning_x
uint32 binning_y
RegionOfInterest roi
MSG: LaserScan
std_msgs/Header header
float32 angle_min
float32 angle_max
float32 angle_increment
float32 time_increment
float32 scan_time
float32 range_min
float32 range_max
float32[] ranges
float32[] intensities
MSG: ChannelFloat32
string name
float32[] values
MSG: PointCloud
Header header
geometry_msgs/Point32[] points
ChannelFloat32[] channels
MSG: PointField
uint8 INT8=1
uint8 UINT8=2
uint8 INT16=3
uint8 UINT16=4
uint8 INT32=5
uint8 UINT32=6
uint8 FLOAT32=7
uint8 FLOAT64=8
string name
uint32 offset
uint8 datatype
uint32 count
MSG: PointCloud2
std_msgs/Header header
uint32 height
uint32 width
PointField[] fields
bool is_bigendian
uint32 point_step
uint32 row_step
uint8[] data
bool is_dense
MSG: Imu
std_msgs/Header header
geometry_msgs/Quaternion orientation
float64[9] orientation_covariance
geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance
geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance
MSG: Range
uint8 ULTRASOUND=0
uint8 INFRARED=1
std_msgs/Header header
uint8 radiation_type
float32 field_of_view
float32 min_range
float32 max_range
float32 range
MSG: Joy
std_msgs/Header header
float32[] axes
int32[] buttons
MSG: NavSatStatus
int8 STATUS_NO_FIX=-1
int8 STATUS_FIX=0
int8 STATUS_SBAS_FIX=1
int8 STATUS_GBAS_FIX=2
int8 status
uint16 SERVICE_GPS=1
uint16 SERVICE_GLONASS=2
uint16 SERVICE_COMPASS=4
uint16 SERVICE_GALILEO=8
uint16 service
MSG: NavSatFix
std_msgs/Header header
NavSatStatus status
float64 latitude
float64 longitude
float64 altitude
float64[9] position_covariance
uint8 COVARIANCE_TYPE_UNKNOWN=0
uint8 COVARIANCE_TYPE_APPROXIMATED=1
uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN=2
uint8 COVARIANCE_TYPE_KNOWN=3
uint8 position_covariance_type
MSG: Temperature
std_msgs/Header header
float64 temperature
float64 variance
MSG: Illuminance
std_msgs/Header header
float64 illuminance
float64 variance
MSG: FluidPressure
std_msgs/Header header
float64 fluid_pressure
float64 variance
MSG: RelativeHumidity
std_msgs/Header header
float64 relative_humidity
float64 variance
MSG: MagneticField
std_msgs/Header header
geometry_msgs/Vector3 magnetic_field
float64[9] magnetic_field_covariance
MSG: BatteryState
# The POWER_SUPPLY_* constants are left out: the codec does not need them.
std_msgs/Header header
float32 voltage
float32 temperature
float32 current
float32 charge
float32 capacity
float32 design_capacity
float32 percentage
uint8 power_supply_status
uint8 power_supply_health
uint8 power_supply_technology
bool present
float32[] cell_voltage
float32[] cell_temperature
string location
string serial_number
";

const NAV_MSGS: &str = "
MSG: Odometry
std_msgs/Header header
string child_frame_id
geometry_msgs/PoseWithCovariance pose
geometry_msgs/TwistWithCovariance twist
MSG: Path
std_msgs/Header header
geometry_msgs/PoseStamped[] poses
MSG: MapMetaData
builtin_interfaces/Time map_load_time
float32 resolution
uint32 width
uint32 height
geometry_msgs/Pose origin
MSG: OccupancyGrid
std_msgs/Header header
MapMetaData info
int8[] data
";

const ROSGRAPH_MSGS: &str = "
MSG: Clock
builtin_interfaces/Time clock
";

const TF2_MSGS: &str = "
MSG: TFMessage
geometry_msgs/TransformStamped[] transforms
";

const STD_SRVS: &str = "
SRV: Empty
---
SRV: SetBool
bool data
---
bool success
string message
SRV: Trigger
---
bool success
string message
";

/// The tutorials' service (CoppeliaSim's simROS2 examples call it).
const EXAMPLE_INTERFACES_SRVS: &str = "
SRV: AddTwoInts
int64 a
int64 b
---
int64 sum
";

/// A goal's identity in ROS 2 actions: 16 random bytes.
const UNIQUE_IDENTIFIER_MSGS: &str = "
MSG: UUID
uint8[16] uuid
";

/// What every ROS 2 action carries besides its own goal, result and feedback: goal
/// identities and the status list an action server keeps (rcl_action's wire types).
const ACTION_MSGS: &str = "
MSG: GoalInfo
unique_identifier_msgs/UUID goal_id
builtin_interfaces/Time stamp
MSG: GoalStatus
int8 STATUS_UNKNOWN=0
int8 STATUS_ACCEPTED=1
int8 STATUS_EXECUTING=2
int8 STATUS_CANCELING=3
int8 STATUS_SUCCEEDED=4
int8 STATUS_CANCELED=5
int8 STATUS_ABORTED=6
GoalInfo goal_info
int8 status
MSG: GoalStatusArray
GoalStatus[] status_list
";

/// An action's cancel service (one type for every action).
const ACTION_MSGS_SRVS: &str = "
SRV: CancelGoal
GoalInfo goal_info
---
int8 ERROR_NONE=0
int8 ERROR_REJECTED=1
int8 ERROR_UNKNOWN_GOAL_ID=2
int8 ERROR_GOAL_TERMINATED=3
int8 return_code
GoalInfo[] goals_canceling
";

/// The tutorials' action (CoppeliaSim's simROS2 action examples use it).
const EXAMPLE_INTERFACES_ACTIONS: &str = "
ACTION: Fibonacci
int32 order
---
int32[] sequence
---
int32[] sequence
";
