//! ROS 2 messages in CDR, the encoding ROS 2 records in bags and MCAP files
//! (`cdr` message encoding, XCDR1 little-endian), with their `ros2msg`
//! schemas: the few types a campaign is told in (docs/USER-GUIDE.md "Robot
//! software"). Definitions as in ROS 2 Humble and later.

/// A CDR message being written: the encapsulation header (CDR, little
/// endian), then the fields, each aligned to its size from the header's end.
#[derive(Debug, Clone)]
pub struct Cdr {
    buf: Vec<u8>,
}

impl Default for Cdr {
    fn default() -> Self {
        Self::new()
    }
}

impl Cdr {
    /// An empty message.
    pub fn new() -> Self {
        Self {
            buf: vec![0x00, 0x01, 0x00, 0x00],
        }
    }

    /// The message's bytes.
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }

    fn align(&mut self, n: usize) {
        let pad = (n - (self.buf.len() - 4) % n) % n;
        self.buf.resize(self.buf.len() + pad, 0);
    }

    /// A `uint8` (also `bool`, `int8` by its bits).
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    /// A `uint32`.
    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// An `int32`.
    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float32`.
    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A `string`: its length with the terminating NUL, the bytes, the NUL.
    pub fn string(&mut self, s: &str) {
        self.len(s.len() + 1);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A sequence's length.
    pub fn len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }

    /// A `uint8[]` (or `int8[]`).
    pub fn bytes(&mut self, b: &[u8]) {
        self.len(b.len());
        self.buf.extend_from_slice(b);
    }

    /// `builtin_interfaces/Time` (or `Duration`) of `ns` nanoseconds.
    pub fn time(&mut self, ns: u64) {
        self.i32(i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX));
        self.u32((ns % 1_000_000_000) as u32);
    }

    /// `std_msgs/Header`.
    pub fn header(&mut self, ns: u64, frame: &str) {
        self.time(ns);
        self.string(frame);
    }

    /// `geometry_msgs/Pose` at `(x, y, z)` turned by `yaw` about z.
    pub fn pose(&mut self, x: f64, y: f64, z: f64, yaw: f64) {
        for v in [x, y, z] {
            self.f64(v);
        }
        self.quaternion(yaw);
    }

    /// `geometry_msgs/Quaternion` of a turn by `yaw` about z.
    pub fn quaternion(&mut self, yaw: f64) {
        let (s, c) = (0.5 * yaw).sin_cos();
        for v in [0.0, 0.0, s, c] {
            self.f64(v);
        }
    }
}

/// Schema names and `ros2msg` texts.
pub mod schema {
    const SEP: &str =
        "\n================================================================================\nMSG: ";

    const TIME: &str = "builtin_interfaces/Time\nint32 sec\nuint32 nanosec";
    const DURATION: &str = "builtin_interfaces/Duration\nint32 sec\nuint32 nanosec";
    const HEADER: &str = "std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id";
    const POINT: &str = "geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z";
    const QUATERNION: &str = "geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w";
    const POSE: &str =
        "geometry_msgs/Pose\ngeometry_msgs/Point position\ngeometry_msgs/Quaternion orientation";
    const VECTOR3: &str = "geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z";
    const COLOR: &str = "std_msgs/ColorRGBA\nfloat32 r\nfloat32 g\nfloat32 b\nfloat32 a";

    /// The definition `top` followed by every type it uses.
    fn text(top: &str, deps: &[&str]) -> String {
        let mut s = top.to_string();
        for d in deps {
            s.push_str(SEP);
            s.push_str(d);
        }
        s
    }

    /// `nav_msgs/OccupancyGrid`.
    pub fn occupancy_grid() -> String {
        text(
            "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data",
            &[
                HEADER,
                TIME,
                "nav_msgs/MapMetaData\nbuiltin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\ngeometry_msgs/Pose origin",
                POSE,
                POINT,
                QUATERNION,
            ],
        )
    }

    /// `sensor_msgs/PointCloud2`.
    pub fn point_cloud2() -> String {
        text(
            "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\nbool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense",
            &[
                HEADER,
                TIME,
                "sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count",
            ],
        )
    }

    /// `geometry_msgs/PoseWithCovarianceStamped`.
    pub fn pose_with_covariance_stamped() -> String {
        text(
            "std_msgs/Header header\ngeometry_msgs/PoseWithCovariance pose",
            &[
                HEADER,
                TIME,
                "geometry_msgs/PoseWithCovariance\ngeometry_msgs/Pose pose\nfloat64[36] covariance",
                POSE,
                POINT,
                QUATERNION,
            ],
        )
    }

    /// `nav_msgs/Path`.
    pub fn path() -> String {
        text(
            "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses",
            &[
                HEADER,
                TIME,
                "geometry_msgs/PoseStamped\nstd_msgs/Header header\ngeometry_msgs/Pose pose",
                POSE,
                POINT,
                QUATERNION,
            ],
        )
    }

    /// `tf2_msgs/TFMessage`.
    pub fn tf_message() -> String {
        text(
            "geometry_msgs/TransformStamped[] transforms",
            &[
                "geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform",
                HEADER,
                TIME,
                "geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation",
                VECTOR3,
                QUATERNION,
            ],
        )
    }

    /// `visualization_msgs/MarkerArray`.
    pub fn marker_array() -> String {
        text(
            "visualization_msgs/Marker[] markers",
            &[
                "visualization_msgs/Marker\nint32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\nint32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\nint32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring texture_resource\nsensor_msgs/CompressedImage texture\nvisualization_msgs/UVCoordinate[] uv_coordinates\nstring text\nstring mesh_resource\nvisualization_msgs/MeshFile mesh_file\nbool mesh_use_embedded_materials",
                HEADER,
                TIME,
                POSE,
                POINT,
                QUATERNION,
                VECTOR3,
                COLOR,
                DURATION,
                "sensor_msgs/CompressedImage\nstd_msgs/Header header\nstring format\nuint8[] data",
                "visualization_msgs/UVCoordinate\nfloat32 u\nfloat32 v",
                "visualization_msgs/MeshFile\nstring filename\nuint8[] data",
            ],
        )
    }
}

/// One `visualization_msgs/Marker` (the fields a plan needs).
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Type (2 sphere, 4 line strip, 9 text).
    pub kind: i32,
    /// Position `(x, y, z)`.
    pub at: [f64; 3],
    /// Scale.
    pub scale: [f64; 3],
    /// Colour RGBA.
    pub color: [f32; 4],
    /// Points of a line strip.
    pub points: Vec<[f64; 3]>,
    /// Text of a text marker.
    pub text: String,
}

/// Sphere, line strip and text marker types.
pub const SPHERE: i32 = 2;
/// A line through `points`.
pub const LINE_STRIP: i32 = 4;
/// Text facing the viewer.
pub const TEXT: i32 = 9;

/// Writes `m` into `c` (stamped `ns`, in `frame`).
pub fn marker(c: &mut Cdr, m: &Marker, ns: u64, frame: &str) {
    c.header(ns, frame);
    c.string(&m.ns);
    c.i32(m.id);
    c.i32(m.kind);
    c.i32(0); // ADD
    c.pose(m.at[0], m.at[1], m.at[2], 0.0);
    for v in m.scale {
        c.f64(v);
    }
    for v in m.color {
        c.f32(v);
    }
    c.time(0); // lifetime: forever
    c.u8(0); // frame_locked
    c.len(m.points.len());
    for p in &m.points {
        for v in p {
            c.f64(*v);
        }
    }
    c.len(0); // colors
    c.string(""); // texture_resource
    c.header(0, ""); // texture: CompressedImage
    c.string("");
    c.bytes(&[]);
    c.len(0); // uv_coordinates
    c.string(&m.text);
    c.string(""); // mesh_resource
    c.string(""); // mesh_file
    c.bytes(&[]);
    c.u8(0); // mesh_use_embedded_materials
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_align_to_their_size_after_the_header() {
        let mut c = Cdr::new();
        c.u8(1);
        c.f64(2.0);
        c.string("ab");
        c.u32(7);
        let b = c.into_bytes();
        assert_eq!(&b[..4], &[0, 1, 0, 0]);
        // u8 at 0, f64 at 8, string length at 16, "ab\0" at 20..23, u32 at 24.
        assert_eq!(b[4], 1);
        assert_eq!(&b[12..20], &2.0f64.to_le_bytes());
        assert_eq!(&b[20..24], &3u32.to_le_bytes());
        assert_eq!(&b[24..27], b"ab\0");
        assert_eq!(&b[28..32], &7u32.to_le_bytes());
        assert_eq!(b.len(), 32);
    }

    #[test]
    fn every_schema_names_each_type_it_uses() {
        for s in [
            schema::occupancy_grid(),
            schema::point_cloud2(),
            schema::pose_with_covariance_stamped(),
            schema::path(),
            schema::tf_message(),
            schema::marker_array(),
        ] {
            let defined: Vec<&str> = s
                .split("MSG: ")
                .skip(1)
                .map(|d| d.lines().next().unwrap_or(""))
                .collect();
            for line in s.lines() {
                let ty = line.split_whitespace().next().unwrap_or("");
                let ty = ty.trim_end_matches("[]");
                let ty = ty.split('[').next().unwrap_or(ty);
                if ty.contains('/') && !line.starts_with("MSG:") {
                    assert!(defined.contains(&ty), "{ty} not defined in\n{s}");
                }
            }
        }
    }
}
