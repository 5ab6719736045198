// Outlines of optical elements, as regions of a surface's parameter plane. For sag surfaces (cad/sag.h) the
// parameter plane is the element's local xy plane in metres, so an outline there is the physical outline.
#pragma once
#include <string>
#include <vector>

#include "pvrr/base/math.h"

namespace pvrr::cad {

class Outline {
 public:
  enum class Shape { Rectangle, Ellipse, Circle, Polygon };

  static Outline rectangle(double width, double height, double corner_radius = 0, Vec2 centre = Vec2(0));
  static Outline ellipse(double width, double height, Vec2 centre = Vec2(0));
  static Outline circle(double diameter, Vec2 centre = Vec2(0));
  // A closed loop (no repeated last point), star-shaped about `centre`; used for CAD trim loops in (u, v).
  static Outline polygon(std::vector<Vec2> loop, Vec2 centre);

  Shape shape() const { return shape_; }
  double width() const { return width_; }
  double height() const { return height_; }
  double cornerRadius() const { return corner_radius_; }
  Vec2 centre() const { return centre_; }
  const std::vector<Vec2>& loop() const { return loop_; }

  bool contains(Vec2 p, double tol = 0) const;
  // Distance from the centre to the boundary along the direction at angle theta (the region is star-shaped
  // about its centre).
  double boundaryRadius(double theta) const;
  // Maps the square [-1,1]^2 onto the region so that the square's boundary lands exactly on the outline
  // (radial scaling about the centre). Grid tessellations use it to put boundary vertices on the outline.
  Vec2 fromSquare(Vec2 s) const;
  std::string describe() const;
  // Axis-aligned bounding box of the region (for a polygon it need not be centred on centre()).
  Vec2 boundsMin() const;
  Vec2 boundsMax() const;
  // The same region: shape, sizes, centre and loop all equal (for caches keyed by an outline).
  bool operator==(const Outline& o) const {
    return shape_ == o.shape_ && width_ == o.width_ && height_ == o.height_ && corner_radius_ == o.corner_radius_ &&
           centre_ == o.centre_ && loop_ == o.loop_;
  }
  bool operator!=(const Outline& o) const { return !(*this == o); }

 private:
  Shape shape_ = Shape::Rectangle;
  double width_ = 1, height_ = 1, corner_radius_ = 0;
  Vec2 centre_{0};
  std::vector<Vec2> loop_;
  std::vector<double> loop_angles_;  // polygon: angle of each loop point about the centre, increasing
  Vec2 lo_{-0.5}, hi_{0.5};          // bounding box
};

}  // namespace pvrr::cad
