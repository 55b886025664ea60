// Builds the optical geometry from TF lookups and compares it with the URDF-loaded model.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <tf2_ros/transform_listener.h>

#include "ros_config.hpp"

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
  ros::NodeHandle nh;
  const OpticsConfig config;
  const auto model = opticalModelFromParams(nh, config);
  const Eigen::Vector2d q(0.05, -0.08);  // rad, well inside ±10°

  ros::Publisher joints = nh.advertise<sensor_msgs::JointState>("joint_states", 1);
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  auto lookup = [&](const std::string& parent, const std::string& child) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(20.0);
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
        return toEigen(buffer.lookupTransform(parent, child, ros::Time(0)).transform);
      }
      catch (const tf2::TransformException&)
      {
        ros::WallDuration(0.05).sleep();
      }
    }
    ADD_FAILURE() << "no transform " << parent << " -> " << child;
    return Eigen::Isometry3d::Identity();
  };

  // Mirror surfaces at the published angles: TF vs the model (1e-9 m, 1e-9 rad: float-free chain).
  const Eigen::Isometry3d mx = lookup("scanhead_base", "mirror_x_defect");
  const Eigen::Isometry3d my = lookup("scanhead_base", "mirror_y_defect");
  EXPECT_LT((mx.matrix() - model->mirrorXPose(q.x()).matrix()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((my.matrix() - model->mirrorYPose(q.y()).matrix()).cwiseAbs().maxCoeff(), 1e-9);

  // A model built only from TF frames traces the same spot.
  OpticalGeometry tf_geometry = model->geometry();
  tf_geometry.source = lookup("scanhead_base", "laser_source_defect");
  tf_geometry.mount_x = lookup("scanhead_base", "galvo_x_mount_defect");
  tf_geometry.mirror_x = lookup("galvo_x_rotor", "mirror_x_defect");
  tf_geometry.mount_y = lookup("scanhead_base", "galvo_y_mount_defect");
  tf_geometry.mirror_y = lookup("galvo_y_rotor", "mirror_y_defect");
  tf_geometry.window_1 = lookup("scanhead_base", "window_1_defect");
  tf_geometry.window_2 = lookup("scanhead_base", "window_2_defect");
  tf_geometry.work_plane = lookup("scanhead_base", "work_plane_defect");
  const OpticalModel from_tf(tf_geometry, config);
  const Eigen::Vector2d a = model->spot(q), b = from_tf.spot(q);
  EXPECT_LT((a - b).norm(), 1e-9) << "model " << a.transpose() << " TF " << b.transpose();
  // The spot itself, in the plane frame from TF: the ray's end lies on the plane (z = 0).
  std::printf("spot at q = (%.3f, %.3f) rad: model (%.9f, %.9f) m, TF (%.9f, %.9f) m\n", q.x(), q.y(), a.x(), a.y(),
              b.x(), b.y());
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "tf_matches_optics");
  ros::NodeHandle nh;  // starts the node before the test body
  return RUN_ALL_TESTS();
}
