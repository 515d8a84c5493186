// The parts of three.js the viewer uses, bundled by build.sh into three.min.js (global THREE).
export {
  WebGLRenderer, Scene, PerspectiveCamera, Group, Mesh, MeshStandardMaterial, MeshBasicMaterial,
  BoxGeometry, SphereGeometry, CylinderGeometry, BufferGeometry, Float32BufferAttribute, Line,
  LineBasicMaterial, LineSegments, GridHelper, ArrowHelper, HemisphereLight, DirectionalLight,
  AmbientLight, Vector3, Quaternion, Color, Raycaster, Vector2, Box3, Sphere, Matrix4, Curve,
  TubeGeometry,
} from "three";
export { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
