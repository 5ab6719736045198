#include "app/cli.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "app/args.h"
#include "app/commands.h"
#include "app/view/viewer.h"
#include "pvrr/base/atomic_file.h"
#include "pvrr/base/error.h"

namespace pvrr::app {

namespace {

struct Command {
  int (*run)(const std::vector<std::string>&);
  const char* summary;
  const char* usage;
};

const std::map<std::string, Command>& commands() {
  static const std::map<std::string, Command> table = {
      {"render",
       {cmdRender, "render a scene to PNG (default: models/car-mirror.json -> out/car-mirror.png)",
        "pvrr render [SCENE] [--mode pvrr|raster|envmap|impostor|raytrace] [--size WxH] [--out FILE.png]\n"
        "            [--gl auto|egl|osmesa] [--set PATH=VALUE]... [--stats FILE.json] [--frames N] [--orbit DEG]\n"
        "            [--time T] [--fps F] [--alternate PATH=VALUE]...\n"
        "  Renders SCENE (default models/car-mirror.json) and prints the output path and the frame time: for one\n"
        "  frame, the steady time (one more frame, not written, every stage run again) and the first, cold frame's\n"
        "  (stats: frame_ms_steady, frame_ms_first).\n"
        "  --stats writes {\"frame_ms\", \"stages\":[{\"name\",\"ms\",\"ran\",\"reason\"}], \"elements\":[...]}.\n"
        "  --frames N renders N frames (the observer turning by --orbit DEG in total about the vertical axis\n"
        "  through the eye; elements attached to the observer turn with it) and reports per-stage counts\n"
        "  (stage_frames: name, frames_ran, frames_skipped, mean_ms, reason: the commonest skip reason, and\n"
        "  reasons: [{frames, reason}] for every kind of reason),\n"
        "  the median frame time (frame_ms), the mean (frame_ms_mean) and the slowest (frame_ms_max). From the\n"
        "  second frame on, maps are drawn with a margin, and later frames reuse them while the view stays\n"
        "  inside it (render.map_reuse_margin_deg).\n"
        "  Each frame's CPU time (process CPU time around it: the calling thread and llvmpipe's) over frames 4 to\n"
        "  N - 1 (the cold and settling frames and the read-back last left out): printed with N > 1 as \"frame CPU\n"
        "  time\" and in the stats as frame_cpu_ms {p10, median, p90, first, last, first_frame}; with\n"
        "  LP_NUM_THREADS=0 and interleaved runs it compares builds and settings (scripts/refine-cost).\n"
        "  --alternate PATH=VALUE (repeatable; steady frames only: no --orbit, no animated scene) draws after each\n"
        "  frame one of a second copy of the scene with these overrides too, in its own context, and prints its\n"
        "  frame CPU time and its ratios to the scene as given (stats: alternate {sets, frame_cpu_ms, ratio_p10,\n"
        "  ratio_median, ratio_paired_median: the median of the frame-by-frame ratios}); the picture written is the\n"
        "  scene as given.\n"
        "  The stats' \"memory\" holds the resident memory after frame 100 (the first frame when N < 100), at\n"
        "  the end, their difference (rss_growth_mb), the peak, and 20 samples over the run.\n"
        "  --time T poses an animated scene (\"animation\" blocks) at T seconds (default 0); with --frames N, frame i\n"
        "  is at T + i / F (--fps, default 30). What moved is updated in place: the moved meshes' buffers, their\n"
        "  own small ray scene, the cube maps only where they are (stats: time_s, fps, animated, frames_moved)."}},
      {"view",
       {cmdView, "open a design-review window: the scene live, head and eye moved by mouse and keys",
        "pvrr view [SCENE] [--mode pvrr|raster|envmap|impostor] [--gl auto|glx|egl] [--size WxH] [--set "
        "PATH=VALUE]...\n"
        "          [--script FILE.json] [--stats FILE.json]\n"
        "  Opens a window (an X display; under xvfb-run without one) rendering SCENE (default models/car-mirror.json)\n"
        "  every frame with the same renderer as pvrr render, and a panel with the frame time, fps and each stage's\n"
        "  time or why it was skipped. Keys: drag or arrows turn the head about the eye; W/S, A/D, R/F move the eye\n"
        "  (1 cm; Shift 10 cm); Home or H returns to the design eye point; 1-4 choose the mode; Tab hides the panel;\n"
        "  F12 writes out/view-N.png, V out/view-N.json (a scene that pvrr render reproduces); Esc quits.\n"
        "  T traces the Embree reference of the view in background threads (again: cancels), shown right of a\n"
        "  split line that a drag moves; E overlays the angular error heat map (pvrr compare's figures in the panel);\n"
        "  O overlays the selected mirror's road footprint (pvrr fov's; scenes with a vehicle).\n"
        "  J/L and K/I turn the selected mirror or lens about its vertex in yaw and pitch (1 deg; Shift 10 deg).\n"
        "  Over a lens, the panel shows pvrr lensmap's readings at the lens point under the mouse.\n"
        "  --script {\"size\":[w,h],\"events\":[{\"at_frame\":N,\"do\":...}]}, do one of: \"set\" (\"path\", "
        "\"value\": as --set),\n"
        "  \"turn_head\" (\"yaw_deg\", \"pitch_deg\": positive turns left, looks up), \"move_eye\" (\"by\": [x,y,z] "
        "metres in\n"
        "  the observer frame: x right, y up, -z forward), \"screenshot\" (\"file\": PNG, the frame without the "
        "panel,\n"
        "  or with it: \"panel\": true, or the window as shown: \"panel\": \"shown\"),\n"
        "  \"save_view\" (\"file\": JSON), \"key\" (\"key\": a GLFW key name of the keys above, \"shift\": "
        "true|false), \"quit\",\n"
        "  \"turn_element\" (\"element\": name, \"yaw_deg\", \"pitch_deg\"), \"move_element\" (\"element\", \"by\":\n"
        "  [x,y,z] metres in its frame: x = up x normal, y up, z normal), \"reference\" (trace it; later events wait),\n"
        "  \"wipe\" (\"x\": 0 all reference .. 1 all mode), \"overlay\" (\"on\": true|false), \"drag\" (\"from\", "
        "\"to\":\n"
        "  [x,y] window pixels, left button), \"cursor\" (\"at\": [x,y]: where the lens readings are taken),\n"
        "  \"time\" (\"t\": seconds of an animated scene, as render --time; \"play\": true|false; key Space plays).\n"
        "  --stats writes {\"frames\", \"fps_median\", \"frame_ms_median\", \"frame_ms_max\", \"mode\", \"size\", "
        "\"gl\",\n"
        "  \"reference\", \"lens_probe\"} at exit\n"
        "  (frame time: the whole loop, render, present, panel and swap)."}},
      {"gl-info",
       {cmdGlInfo, "print the GL backend, GL_VERSION and GL_RENDERER",
        "pvrr gl-info [--gl auto|egl|osmesa]\n  The backend can also be chosen with the PVRR_GL variable."}},
      {"trace",
       {cmdTrace, "trace one reference ray and print its path as JSON",
        "pvrr trace SCENE (--ray OX,OY,OZ,DX,DY,DZ | --pixel X,Y [--size WxH]) [--wavelength NM] [--set "
        "PATH=VALUE]...\n"
        "  Pixel centres are at +0.5, the origin is the top-left corner. Prints\n"
        "  {\"segments\":[{\"origin\",\"direction\",\"event\",\"element\",\"point\",\"normal\",\"n1\",\"n2\"}]}."}},
      {"vertices",
       {cmdVertices, "write the per-vertex PVRR data of a scene as CSV (+ JSON cameras) or VTP",
        "pvrr vertices SCENE [--element NAME] [--set PATH=VALUE]... --out FILE.csv|FILE.vtp\n"
        "  CSV columns: element,patch,vertex,channel,px,py,pz,nx,ny,nz,dx,dy,dz,status,hx,hy,hz,s,t\n"
        "  (+ ix,iy,iz,bx,by,bz,bnx,bny,bnz for lenses); FILE.json beside it holds each patch's camera."}},
      {"compare",
       {cmdCompare, "render the reference and each mode; write images, error heat maps and metrics.json",
        "pvrr compare SCENE [--modes pvrr,envmap,impostor,raster] [--size WxH] [--frames N] [--gl B] [--set "
        "PATH=VALUE]... --out DIR\n"
        "             [--time T] [--fps F]\n"
        "  Writes DIR/reference.png, DIR/MODE.png, DIR/MODE-error.png and DIR/metrics.json: per mode the frame\n"
        "  time, stages and angular error (median, p95, max), split into the zooming region and the rest\n"
        "  (\"regions\"); with rgb dispersion also per colour channel (\"channels\") and the fringes' sign\n"
        "  (\"fringe\"). Pixels whose reference path ended at render.max_depth have no seen point: they are\n"
        "  compared by colour only (\"depth_limit\"). metrics.json's \"definitions\" says how each figure is measured.\n"
        "  --time T: the scene's animation posed at T seconds. --fps F: over time, --frames N instants T + i / F;\n"
        "  metrics.json's \"over_time\" holds each frame's error per mode and each mode's worst frame (largest\n"
        "  p95), DIR/frames.csv the rows frame,time_s,mode,pixels,median_arcmin,p95_arcmin,max_arcmin,psnr_db."}},
      {"sweep",
       {cmdSweep, "compare over a grid of tessellations and map sizes; write sweep.csv and error-vs-time plots",
        "pvrr sweep SCENE [--tessellation N1,N2,...] [--map-size S1,S2,...] [--vary PATH=V1,V2,...]... [--modes "
        "M1,...]\n"
        "           [--size WxH] [--frames N] [--gl B] --out DIR\n"
        "  Writes DIR/sweep.csv (mode,tessellation,map_size,vertices,frame_ms,median_arcmin,p95_arcmin,max_arcmin,\n"
        "  psnr_db,reference_ms,vary), DIR/error_vs_time.png and .svg, DIR/error_vs_vertices.png.\n"
        "  --map-size fixes each map's longer side (render.map_texels_per_pixel=0 unless --set says otherwise);\n"
        "  without it, the scene's own map sizing."}},
      {"plot", {cmdPlot, "redraw the plots of a sweep from its CSV", "pvrr plot DIR/sweep.csv [--out DIR]"}},
      {"lensmap",
       {cmdLensmap, "power, astigmatism, prism, distortion and colour maps of a spectacle lens as worn",
        "pvrr lensmap SCENE [--element NAME] [--grid N] [--gaze-max DEG] [--object-distance M] [--set PATH=VALUE]... "
        "--out DIR\n"
        "  Per gaze (Fick angles, N x N from -DEG to +DEG, default 41 and 40), the chief ray through the eye's centre\n"
        "  of rotation (the lens's \"eye\" block, default 25.5 mm behind its eye-side vertex) traced exactly, and the\n"
        "  wavefront of an object at infinity (or M metres from the rotation centre) on the vertex sphere.\n"
        "  Writes DIR/lensmap.csv (gaze_x_deg,gaze_y_deg,lens_x_mm,lens_y_mm,sphere_d,cylinder_d,axis_deg,\n"
        "  mean_power_d,power_error_d,unwanted_cylinder_d,prism_h,prism_v,distortion_pct,lateral_colour_arcmin,\n"
        "  tangential_d,sagittal_d,prentice_h,prentice_v,object_x_deg,object_y_deg; empty cells where no ray passes),\n"
        "  DIR/lensmap.json (conventions, prescription, centre, ranges, empty gazes, focimeter reading) and maps as\n"
        "  PNG and SVG: power_error, cylinder, prism, lateral_colour, distortion. Conventions: docs/lensmap.md."}},
      {"fov",
       {cmdFov, "a mirror's field of view on the road, checked against regulation zones",
        "pvrr fov SCENE [--element NAME] [--regulation ID]... [--eyes both|left|right|ellipse] [--samples N]\n"
        "         [--aim [--aim-range DEG]] [--set PATH=VALUE]... --out DIR\n"
        "  From each of the vehicle's ocular points (the scene's \"vehicle\" block), N x N rays (default 121) through\n"
        "  the mirror, reflected exactly and continued to the road; the footprint per eye and the share of each\n"
        "  regulation zone (models/regulations/ID.json; default: vehicle.regulations) covered and obstructed.\n"
        "  Writes DIR/fov.json (element, eyes, footprint polygons in the vehicle frame, zones with\n"
        "  covered_fraction, obstructed_fraction, pass, verified; surface: mean and principal radii, magnification\n"
        "  range, R46 Annex 7's three-point mean radius), the plan view DIR/fov.png and .svg, and the magnification\n"
        "  map DIR/magnification.png and .svg. --eyes ellipse: over vehicle.eye_ellipse's samples, a zone point seen\n"
        "  from any. --aim: the mirror's yaw and pitch about its pivot (element.pivot, default its vertex; within\n"
        "  DEG, default 10) that meets every zone with the largest margin, checked afresh: fov.json \"aim\",\n"
        "  DIR/aimed.json (the scene with the new pose) and DIR/aimed/fov.png and .svg. Conventions: docs/fov.md."}},
      {"caustic",
       {cmdCaustic, "the reference's caustic of mirrors and lenses on a receiving surface: irradiance map and figures",
        "pvrr caustic SCENE [--receiver NAME] [--window CU,CV,W,H] [--cells N] [--photons N] [--seed N]\n"
        "         [--element NAME] [--set PATH=VALUE]... --out DIR\n"
        "  Light tracing from the directional and point lights through the elements (N x N photons per light,\n"
        "  element and wavelength sample, default 512, at most 2048; render.dispersion sets the samples) onto the\n"
        "  receiver: a quad or ground of the scene, or a mesh that is a height field over a plane (a bowl, a\n"
        "  cylinder segment: mapped over that plane, per unit area of its surface) (default: the one receiving the\n"
        "  most caustic power). The map covers the window (receiver coordinates in metres about its centre;\n"
        "  default: around the light that lands) in N cells along its longer side (default 160). Writes\n"
        "  DIR/caustic.png (false colour, colour bar in W/m^2), DIR/caustic-colour.png (the irradiance in colour),\n"
        "  DIR/caustic.csv (per cell:\n"
        "  i,j,u_m,v_m,x_m,y_m,z_m,irradiance_r,irradiance_g,irradiance_b,irradiance,stderr) and DIR/caustic.json\n"
        "  (peak, spot, power, photon counts). Method and accuracy: docs/caustics.md."}},
      {"mesh",
       {cmdMesh, "tessellate a surface and write it as OBJ, PLY or VTP",
        "pvrr mesh (SURFACE_FILE | SCENE --element NAME) [--tessellation N | --tolerance T] --out FILE.obj|.ply|.vtp"}},
  };
  return table;
}

void printHelp() {
  std::printf("pvrr: per-vertex reflection and refraction for curved mirrors and lenses\n\nusage: pvrr COMMAND [ARGS]\n\n");
  for (const auto& [name, c] : commands()) std::printf("  %-9s %s\n", name.c_str(), c.summary);
  std::printf("\n  help CMD  usage of one command\n\nExit codes: 0 success, 1 usage or input error, 2 internal error.\n");
}

}  // namespace

int runMain(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.empty() || args[0] == "help" || args[0] == "--help" || args[0] == "-h") {
      if (args.size() >= 2) {
        auto it = commands().find(args[1]);
        if (it == commands().end()) throw Error("pvrr help: unknown command \"" + args[1] + "\"");
        std::printf("%s\n", it->second.usage);
        return 0;
      }
      printHelp();
      return args.empty() ? 1 : 0;
    }
    auto it = commands().find(args[0]);
    if (it == commands().end()) {
      std::vector<std::string> names;
      for (const auto& kv : commands()) names.push_back(kv.first);
      std::string hint = nearest(args[0], names);
      throw Error("pvrr: unknown command \"" + args[0] + "\"" + (hint.empty() ? "" : "; did you mean \"" + hint + "\"?") +
                  " (see: pvrr help)");
    }
    // Test-only hook (tests/app/input_cli_test.cpp): exercises the internal-error path (exit code 2), which no
    // valid or invalid input should reach. The variable's name says what it is for.
    if (const char* hook = std::getenv("PVRR_TEST_ONLY_FORCE_INTERNAL_ERROR"); hook && std::string(hook) == "1")
      PVRR_CHECK(false, << "(forced by PVRR_TEST_ONLY_FORCE_INTERNAL_ERROR=1 before running \"" << args[0] << "\")");
    // Every file the command writes appears when it succeeds, none when it fails at any point.
    OutputTransaction outputs;
    const int rc = it->second.run(std::vector<std::string>(args.begin() + 1, args.end()));
    if (rc == 0) outputs.commit();
    return rc;
  } catch (const Error& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pvrr: internal error: %s\n", e.what());
    return 2;
  } catch (...) {
    std::fprintf(stderr, "pvrr: internal error: an exception of unknown type\n");
    return 2;
  }
}

}  // namespace pvrr::app
