"""The independent ROS 2 peer of test_ros2.py: Eclipse Cyclone DDS from PyPI (the core of
ROS 2's rmw_cyclonedds_cpp) with ROS 2's name mangling written out by hand, so that
nothing here comes from gantry.

ROS 2 maps topic ``/x`` to DDS topic ``rt/x`` and message type ``pkg/msg/T`` to DDS type
``pkg::msg::dds_::T_``; a service ``/s`` is two topics, ``rq/sRequest`` and
``rr/sReply``, whose samples begin (in rmw_cyclonedds' mapping) with the client's id and
a sequence number. The dataclasses below are those messages' IDL, field for field.
"""


import os
import random
import time
from dataclasses import dataclass

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float32, float64, int8, int32, int64, sequence, uint8, uint32, uint64
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
class Clock(IdlStruct, typename="rosgraph_msgs::msg::dds_::Clock_"):
    clock: Time


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class Bool(IdlStruct, typename="std_msgs::msg::dds_::Bool_"):
    data: bool


@dataclass
class Float32(IdlStruct, typename="std_msgs::msg::dds_::Float32_"):
    data: float32


@dataclass
class Float64(IdlStruct, typename="std_msgs::msg::dds_::Float64_"):
    data: float64


@dataclass
class MultiArrayDimension(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayDimension_"):
    label: str
    size: uint32
    stride: uint32


@dataclass
class MultiArrayLayout(IdlStruct, typename="std_msgs::msg::dds_::MultiArrayLayout_"):
    dim: sequence[MultiArrayDimension]
    data_offset: uint32


@dataclass
class Float64MultiArray(IdlStruct, typename="std_msgs::msg::dds_::Float64MultiArray_"):
    layout: MultiArrayLayout
    data: sequence[float64]


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64
    y: float64
    z: float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64
    y: float64
    z: float64
    w: float64


@dataclass
class Transform(IdlStruct, typename="geometry_msgs::msg::dds_::Transform_"):
    translation: Vector3
    rotation: Quaternion


@dataclass
class TransformStamped(IdlStruct, typename="geometry_msgs::msg::dds_::TransformStamped_"):
    header: Header
    child_frame_id: str
    transform: Transform


@dataclass
class TFMessage(IdlStruct, typename="tf2_msgs::msg::dds_::TFMessage_"):
    transforms: sequence[TransformStamped]


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3
    angular: Vector3


@dataclass
class TruncatedTwist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    """Bad input: a `Twist` by name with one float where six belong."""

    linear_x: float64


@dataclass
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header
    name: sequence[str]
    position: sequence[float64]
    velocity: sequence[float64]
    effort: sequence[float64]


@dataclass
class Image(IdlStruct, typename="sensor_msgs::msg::dds_::Image_"):
    header: Header
    height: uint32
    width: uint32
    encoding: str
    is_bigendian: uint8
    step: uint32
    data: sequence[uint8]


@dataclass
class RegionOfInterest(IdlStruct, typename="sensor_msgs::msg::dds_::RegionOfInterest_"):
    x_offset: uint32
    y_offset: uint32
    height: uint32
    width: uint32
    do_rectify: bool


@dataclass
class CameraInfo(IdlStruct, typename="sensor_msgs::msg::dds_::CameraInfo_"):
    header: Header
    height: uint32
    width: uint32
    distortion_model: str
    d: sequence[float64]
    k: array[float64, 9]
    r: array[float64, 9]
    p: array[float64, 12]
    binning_x: uint32
    binning_y: uint32
    roi: RegionOfInterest


@dataclass
class SetBoolRequest(IdlStruct, typename="std_srvs::srv::dds_::SetBool_Request_"):
    client_guid: uint64
    sequence_number: int64
    data: bool


@dataclass
class SetBoolResponse(IdlStruct, typename="std_srvs::srv::dds_::SetBool_Response_"):
    client_guid: uint64
    sequence_number: int64
    success: bool
    message: str


@dataclass
class AddTwoIntsRequest(IdlStruct, typename="example_interfaces::srv::dds_::AddTwoInts_Request_"):
    client_guid: uint64
    sequence_number: int64
    a: int64
    b: int64


@dataclass
class AddTwoIntsResponse(IdlStruct, typename="example_interfaces::srv::dds_::AddTwoInts_Response_"):
    client_guid: uint64
    sequence_number: int64
    sum: int64


# ---- actions: rcl_action's wire types around example_interfaces/action/Fibonacci ----


@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: array[uint8, 16]


@dataclass
class GoalInfo(IdlStruct, typename="action_msgs::msg::dds_::GoalInfo_"):
    goal_id: UUID
    stamp: Time


@dataclass
class GoalStatus(IdlStruct, typename="action_msgs::msg::dds_::GoalStatus_"):
    goal_info: GoalInfo
    status: int8


@dataclass
class GoalStatusArray(IdlStruct, typename="action_msgs::msg::dds_::GoalStatusArray_"):
    status_list: sequence[GoalStatus]


@dataclass
class CancelGoalRequest(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Request_"):
    client_guid: uint64
    sequence_number: int64
    goal_info: GoalInfo


@dataclass
class CancelGoalResponse(IdlStruct, typename="action_msgs::srv::dds_::CancelGoal_Response_"):
    client_guid: uint64
    sequence_number: int64
    return_code: int8
    goals_canceling: sequence[GoalInfo]


@dataclass
class FibonacciGoal(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_Goal_"):
    order: int32


@dataclass
class FibonacciResult(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_Result_"):
    sequence: sequence[int32]


@dataclass
class FibonacciFeedback(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_Feedback_"):
    sequence: sequence[int32]


@dataclass
class FibonacciSendGoalRequest(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_SendGoal_Request_"):
    client_guid: uint64
    sequence_number: int64
    goal_id: UUID
    goal: FibonacciGoal


@dataclass
class FibonacciSendGoalResponse(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_SendGoal_Response_"):
    client_guid: uint64
    sequence_number: int64
    accepted: bool
    stamp: Time


@dataclass
class FibonacciGetResultRequest(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_GetResult_Request_"):
    client_guid: uint64
    sequence_number: int64
    goal_id: UUID


@dataclass
class FibonacciGetResultResponse(
    IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_GetResult_Response_"
):
    client_guid: uint64
    sequence_number: int64
    status: int8
    result: FibonacciResult


@dataclass
class FibonacciFeedbackMessage(IdlStruct, typename="example_interfaces::action::dds_::Fibonacci_FeedbackMessage_"):
    goal_id: UUID
    feedback: FibonacciFeedback


class FibonacciEndpoints:
    """The peer's side of action ``name`` (rcl_action's layout): as a client
    (``serving=False``) it writes requests and reads replies, feedback and status; as a
    server the other way round."""

    def __init__(self, peer: "Peer", name: str, serving: bool):
        base = name.strip("/")
        pairs = {
            "send_goal": (FibonacciSendGoalRequest, FibonacciSendGoalResponse),
            "cancel_goal": (CancelGoalRequest, CancelGoalResponse),
            "get_result": (FibonacciGetResultRequest, FibonacciGetResultResponse),
        }
        self.requests, self.replies = {}, {}
        for service, (rq, rr) in pairs.items():
            rq_topic = f"rq/{base}/_action/{service}Request"
            rr_topic = f"rr/{base}/_action/{service}Reply"
            if serving:
                self.requests[service] = peer.reader(rq_topic, rq)
                self.replies[service] = peer.writer(rr_topic, rr)
            else:
                self.requests[service] = peer.writer(rq_topic, rq)
                self.replies[service] = peer.reader(rr_topic, rr)
        feedback = f"rt/{base}/_action/feedback"
        status = f"rt/{base}/_action/status"
        if serving:
            self.feedback = peer.writer(feedback, FibonacciFeedbackMessage)
            self.status = peer.writer(status, GoalStatusArray, LATCHED)
        else:
            self.feedback = peer.reader(feedback, FibonacciFeedbackMessage)
            self.status = peer.reader(status, GoalStatusArray, LATCHED)


def loopback_config() -> str:
    """Cyclone on the loopback interface, as ROS_LOCALHOST_ONLY=1 configures it (gantry
    joins the graph on this host only by default). Discovery goes by unicast to the
    well-known ports of 127.0.0.1, where RustDDS announces itself too: Linux's `lo`
    often has no multicast (as on the CI machines), and multicast discovery there took
    seconds instead of well under one."""
    return (
        "<CycloneDDS><Domain><General><Interfaces>"
        '<NetworkInterface address="127.0.0.1"/>'
        "</Interfaces><AllowMulticast>false</AllowMulticast></General>"
        "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
        '<Peers><Peer address="127.0.0.1"/></Peers></Discovery>'
        "</Domain></CycloneDDS>"
    )


def free_domain() -> int:
    """A domain id no other test run on this host is likely to use."""
    return random.Random(os.getpid() ^ time.time_ns()).randrange(100, 230)


RELIABLE = Qos(Policy.Reliability.Reliable(duration(milliseconds=200)), Policy.History.KeepLast(10))
LATCHED = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=200)),
    Policy.Durability.TransientLocal,
    Policy.History.KeepLast(1),
)


class Peer:
    """One Cyclone DDS participant in ``domain``."""

    def __init__(self, domain: int):
        os.environ["CYCLONEDDS_URI"] = loopback_config()
        self.dp = DomainParticipant(domain)

    def reader(self, topic, kind, qos=RELIABLE):
        return DataReader(self.dp, Topic(self.dp, topic, kind, qos=qos), qos=qos)

    def writer(self, topic, kind, qos=RELIABLE):
        return DataWriter(self.dp, Topic(self.dp, topic, kind, qos=qos), qos=qos)


def take_until(reader, done, timeout=20.0, what="samples"):
    """Samples from ``reader`` until ``done(samples)`` holds; fails after ``timeout`` s."""
    got: list = []
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        got.extend(reader.take(N=1000))
        if done(got):
            return got
        time.sleep(0.02)
    raise AssertionError(f"timed out waiting for {what}: got {len(got)}")
