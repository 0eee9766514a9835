// The check that a pipeline asked for the colour alone (OutputLayers::Colour) gives the colours
// of every layer, on any device: test_pipeline runs it on the CPU, test_pipeline_gl on OpenGL.
#pragma once

#include <gtest/gtest.h>

#include <utility>

#include "TestSupport.h"
#include "pipeline/FramePipeline.h"
#include "raycast/RaycastScenes.h"

namespace flipscope::testing {

/// Renders the ball scene from two views on `device` with every layer, then with the colour
/// alone from another pipeline, and expects the same colours and no other layer; asked for every
/// layer again, the last frame gives them all. Throws what FramePipeline's constructor throws
/// (gl::Unavailable) before any expectation.
inline void expectTheColourAloneIsTheColourOfAllLayers(DeviceChoice device) {
  TempDir dir("pipeline");
  const BallScene ball;
  ball.makeStore(dir.path() / "store");
  Camera farther = ball.camera();
  farther.eye = farther.target + (farther.eye - farther.target) * 1.5;
  // Every layer, of two different views, from one pipeline...
  FramePipeline layers(BrickStore::open(dir.path() / "store"), device, ball.settings(), SurfaceSettings{});
  const RenderImage near = layers.render(0, ball.camera()).image;
  const RenderImage far = layers.render(0, farther).image;
  const std::size_t n = std::size_t(near.width) * near.height;
  ASSERT_EQ(near.depth.size(), n);
  ASSERT_EQ(near.normal.size(), n);
  ASSERT_EQ(near.thickness.size(), n);
  ASSERT_EQ(near.foam.size(), n) << "the volumetric foam is the default";
  ASSERT_NE(near.rgba, far.rgba);
  // ...and the colour alone from another, from its first frame on: the same colours.
  FramePipeline colourOnly(BrickStore::open(dir.path() / "store"), device, ball.settings(),
                           SurfaceSettings{});
  colourOnly.setOutputLayers(OutputLayers::Colour);
  for (const auto& [camera, expected] : {std::pair{ball.camera(), &near}, std::pair{farther, &far}}) {
    const RenderImage colour = colourOnly.render(0, camera).image;
    EXPECT_EQ(colour.width, expected->width);
    EXPECT_EQ(colour.height, expected->height);
    EXPECT_EQ(colour.rgba, expected->rgba);
    EXPECT_TRUE(colour.depth.empty() && colour.unsmoothedDepth.empty() && colour.thickness.empty() &&
                colour.normal.empty() && colour.foam.empty() && colour.attribute.empty());
  }
  // Asked for again with every layer, the last frame gives them all.
  colourOnly.setOutputLayers(OutputLayers::All);
  const RenderImage again = colourOnly.readOutput().image;
  EXPECT_EQ(again.rgba, far.rgba);
  EXPECT_EQ(again.depth, far.depth);
  EXPECT_EQ(again.unsmoothedDepth, far.unsmoothedDepth);
  EXPECT_EQ(again.normal, far.normal);
  EXPECT_EQ(again.thickness, far.thickness);
  EXPECT_EQ(again.foam, far.foam);
}

}  // namespace flipscope::testing
