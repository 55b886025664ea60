// The frames TF broadcasts for a defective machine (its URDF generated from a defect set) equal
// the optical model's (the nominal URDF with the set applied), at scattered joint angles.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/transform_listener.h>

#include "ros_config.hpp"
#include "scanhead/optics/optics_loading.hpp"

using namespace scanhead;

namespace
{
Eigen::Isometry3d toEigen(const geometry_msgs::Transform& t)
{
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  out.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z).toRotationMatrix();
  return out;
}
}  // namespace

TEST(TfMatchesOptics, MirrorsAndSpotAgree)
{
  ros::NodeHandle nh, private_nh("~");
  OpticsConfig config;
  private_nh.param("defects", config.defects, std::string("nominal"));
  // The model the batch runner uses: nominal URDF file + the set; TF: the generated URDF.
  const OpticalModel model = loadOpticalModel(config);
  const auto from_description = opticalModelFromParams(nh, config);  // also checks they agree

  ros::Publisher joints = nh.advertise<sensor_msgs::JointState>("joint_states", 1);
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  // The pose of \p child at joint angles \p q: published until TF shows these angles (the mirror
  // frames move with them), or a failure after 20 s.
  auto lookup = [&](const std::string& parent, const std::string& child, const Eigen::Vector2d& q,
                    const Eigen::Isometry3d* expected) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(20.0);
    Eigen::Isometry3d last = Eigen::Isometry3d::Identity();
    while (ros::WallTime::now() < deadline)
    {
      sensor_msgs::JointState state;
      state.header.stamp = ros::Time::now();
      state.name = {"galvo_x", "galvo_y"};
      state.position = {q.x(), q.y()};
      joints.publish(state);
      ros::spinOnce();
      try
      {
        last = toEigen(buffer.lookupTransform(parent, child, ros::Time(0)).transform);
        if (expected == nullptr || (last.matrix() - expected->matrix()).cwiseAbs().maxCoeff() < 1e-6)
          return last;  // these angles' frame (a stale one is off by the angle change)
      }
      catch (const tf2::TransformException&)
      {
      }
      ros::WallDuration(0.05).sleep();
    }
    ADD_FAILURE() << "no transform " << parent << " -> " << child << " at the angles";
    return last;
  };

  // Mirror surfaces at scattered angles within the field: TF vs the model within 1e-12 (m, and
  // rotation-matrix entries), the tolerance; the chain is in double throughout.
  // Five scattered angle pairs in ±0.12 rad (fixed: the same on every platform).
  const Eigen::Vector2d angles[] = {
      {0.0731, -0.1142}, {-0.1187, 0.0316}, {0.0094, 0.1063}, {-0.0528, -0.0779}, {0.1196, 0.0851}};
  double worst = 0.0;
  for (const Eigen::Vector2d& q : angles)
  {
    const Eigen::Isometry3d want_x = model.mirrorXPose(q.x()), want_y = model.mirrorYPose(q.y());
    const Eigen::Isometry3d mx = lookup("scanhead_base", "mirror_x_defect", q, &want_x);
    const Eigen::Isometry3d my = lookup("scanhead_base", "mirror_y_defect", q, &want_y);
    worst = std::max({worst, (mx.matrix() - want_x.matrix()).cwiseAbs().maxCoeff(),
                      (my.matrix() - want_y.matrix()).cwiseAbs().maxCoeff()});
    EXPECT_LT((from_description->spot(q) - model.spot(q)).norm(), 1e-12) << q.transpose();
  }
  EXPECT_LT(worst, 1e-12);

  // The static frames, and a model built only from TF frames traces the same spots.
  const Eigen::Vector2d q(0.05, -0.08);
  OpticalGeometry tf_geometry = model.geometry();
  tf_geometry.source = lookup("scanhead_base", "laser_source_defect", q, nullptr);
  tf_geometry.mount_x = lookup("scanhead_base", "galvo_x_mount_defect", q, nullptr);
  tf_geometry.mirror_x = lookup("galvo_x_rotor", "mirror_x_defect", q, nullptr);
  tf_geometry.mount_y = lookup("scanhead_base", "galvo_y_mount_defect", q, nullptr);
  tf_geometry.mirror_y = lookup("galvo_y_rotor", "mirror_y_defect", q, nullptr);
  tf_geometry.window_1 = lookup("scanhead_base", "window_1_defect", q, nullptr);
  tf_geometry.window_2 = lookup("scanhead_base", "window_2_defect", q, nullptr);
  tf_geometry.work_plane = lookup("scanhead_base", "work_plane_defect", q, nullptr);
  const OpticalModel from_tf(tf_geometry, config);
  const Eigen::Vector2d a = model.spot(q), b = from_tf.spot(q);
  EXPECT_LT((a - b).norm(), 1e-12) << "model " << a.transpose() << " TF " << b.transpose();
  std::printf(
      "defects %s: mirror frames TF vs model within %.2e; spot at q = (%.3f, %.3f) rad: model (%.9f, %.9f) m, "
      "TF (%.9f, %.9f) m\n",
      config.defects.c_str(), worst, q.x(), q.y(), a.x(), a.y(), b.x(), b.y());
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "tf_matches_optics");
  ros::NodeHandle nh;  // starts the node before the test body
  return RUN_ALL_TESTS();
}
