// Scripted runs of `pvrr view` (--script FILE.json), for tests and demos:
//   {"size": [w, h], "events": [{"at_frame": N, "do": ..., ...}, ...]}
// Each event runs before frame N is drawn (frames count from 0). Parsed and validated whole before the window
// opens; every problem throws pvrr::Error "<file>: <json.path>: <message>" (syntax: "<file>:LINE:COL: ...").
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr::app::view {

// clang-format off
enum class EventKind { Set, TurnHead, MoveEye, Screenshot, SaveView, Quit, Key, Reference, Wipe, Overlay, Drag,
                       TurnElement, Cursor, MoveElement, Time };
// clang-format on

struct ScriptEvent {
  int at_frame = 0;
  EventKind kind = EventKind::Quit;
  std::string where;  // "events[3]", for messages about the event at run time
  // set: a scene path as --set takes it and its value as JSON text ("render.mode", "\"envmap\"").
  std::string path, value_json;
  double yaw_deg = 0, pitch_deg = 0;  // turn_head: positive yaw turns left, positive pitch looks up;
                                      // turn_element: app/view/element_pose.h
  std::string element;                // turn_element, move_element: the element's name
                                      // move_element: "by" (by_m) in metres in the element's frame
  Vec2 at_px{0};                      // cursor: where the lens probe reads, window pixels (as the mouse hovering)
  Vec3 by_m{0};                       // move_eye: metres in the observer frame (x right, y up, -z forward)
  std::string file;                   // screenshot, save_view
  bool with_panel = false;            // screenshot: with the panel over the frame ("panel": true)
  // screenshot: the window as the display shows it after the frame ("panel": "shown"), read from the X server:
  // where a frame kept the panel (app/view/panel_cache.h), its pixels are those an earlier frame showed
  bool shown = false;
  int key = 0;                        // key: the GLFW key code of "key" (a GLFW key name: "W", "LEFT", "HOME")
  bool shift = false;                 // key: with Shift held ("shift": true)
  // reference: start the live reference of the current view and run no later event until it is finished
  // (the window keeps drawing meanwhile).
  double wipe_x = 0.5;        // wipe: the split line's position, 0 (all reference) to 1 (all mode)
  bool on = false;            // overlay: show ("on": true) or hide the error heat map; time: play on from t ("play")
  double time_s = 0;          // time: the animated scene's time "t" (s), as pvrr render --time; playing stops
  Vec2 from_px{0}, to_px{0};  // drag (left button): press at "from", move to "to", release; window pixels
};

struct Script {
  int width = 0, height = 0;  // 0: not given
  std::vector<ScriptEvent> events;  // in the order they run (by at_frame, then file order)
};

// `name` prefixes every message.
Script parseScript(const std::string& json_text, const std::string& name);
Script loadScript(const std::string& path);

}  // namespace pvrr::app::view
