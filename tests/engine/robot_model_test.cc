#include "pixelgym/engine/robot_model.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace pixelgym::engine {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

std::string data(const std::string& name) {
  return std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf/" + name;
}

struct AssetCase {
  std::string file;
  std::size_t links;
  std::size_t movable_joints;
  friend void PrintTo(const AssetCase& c, std::ostream* out) { *out << c.file; }
};

class AssetTest : public ::testing::TestWithParam<AssetCase> {};

TEST_P(AssetTest, LoadsWithTheExpectedStructure) {
  MeshCache meshes;
  const auto model = parse_urdf(asset_path(GetParam().file), meshes);
  EXPECT_EQ(model->links().size(), GetParam().links);
  EXPECT_EQ(model->movable_joints().size(), GetParam().movable_joints);
  EXPECT_EQ(model->joints().size() + 1, model->links().size());
  for (std::size_t j = 0; j < model->joints().size(); ++j) {
    EXPECT_EQ(model->joints()[j].child_link, static_cast<int>(j) + 1);
    EXPECT_LT(model->joints()[j].parent_link, model->joints()[j].child_link);
  }
  for (const LinkModel& link : model->links()) {
    for (const VisualElement& visual : link.visuals) {
      if (visual.geometry.type == GeometryType::kMesh) {
        EXPECT_NE(visual.geometry.mesh, nullptr);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    EveryAsset, AssetTest,
    ::testing::Values(
        AssetCase{"cartpole/cartpole.urdf", 3, 2}, AssetCase{"cartpole/cartpole_v1.urdf", 3, 2},
        AssetCase{"pendulum/pendulum.urdf", 2, 1}, AssetCase{"acrobot/acrobot.urdf", 3, 2},
        AssetCase{"reacher/reacher.urdf", 4, 2}, AssetCase{"reacher/reacher_v1.urdf", 4, 2},
        AssetCase{"arm/arm.urdf", 10, 7}, AssetCase{"objects/table.urdf", 1, 0},
        AssetCase{"objects/cube.urdf", 1, 0}, AssetCase{"objects/target.urdf", 1, 0},
        AssetCase{"cheetah/cheetah.urdf", 10, 9}, AssetCase{"walker/walker.urdf", 10, 9},
        AssetCase{"finger/finger.urdf", 4, 3}, AssetCase{"ball_in_cup/ball_in_cup.urdf", 5, 4}),
    [](const ::testing::TestParamInfo<AssetCase>& param_info) {
      std::string name = std::filesystem::path(param_info.param.file).stem().string();
      return name;
    });

TEST(RobotModelTest, EveryUrdfUnderAssetsIsCovered) {
  int count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(
           std::string(PIXELGYM_SOURCE_DIR) + "/assets")) {
    if (entry.path().extension() == ".urdf") ++count;
  }
  EXPECT_EQ(count, 14) << "a new asset needs a line in AssetTest";
}

TEST(RobotModelTest, ArmIsMadeOfMeshesWithLimitsAndInertias) {
  MeshCache meshes;
  const auto arm = parse_urdf(asset_path("arm/arm.urdf"), meshes);
  EXPECT_EQ(arm->name(), "arm");
  for (int j : arm->movable_joints()) {
    const JointModel& joint = arm->joints()[static_cast<std::size_t>(j)];
    EXPECT_EQ(joint.type, JointType::kRevolute);
    EXPECT_TRUE(joint.has_limits);
    EXPECT_LT(joint.lower, joint.upper);
    EXPECT_GT(joint.effort_limit, 0);
    const LinkModel& link = arm->links()[static_cast<std::size_t>(joint.child_link)];
    ASSERT_EQ(link.visuals.size(), 1U);
    EXPECT_EQ(link.visuals[0].geometry.type, GeometryType::kMesh);
    ASSERT_EQ(link.collisions.size(), 1U);
    EXPECT_EQ(link.collisions[0].geometry.type, GeometryType::kMesh);
    EXPECT_GT(link.inertial.mass_kg, 0);
  }
  EXPECT_NEAR(arm->total_mass_kg(), 6.0 + 16.8 + 0.4, 1e-9);
  EXPECT_NO_THROW(arm->link_index("end_effector"));
  EXPECT_THROW(arm->link_index("nope"), std::out_of_range);
}

TEST(RobotModelTest, CapsulesMaterialsAndJointDetails) {
  MeshCache meshes;
  const auto cartpole = parse_urdf(asset_path("cartpole/cartpole.urdf"), meshes);
  const LinkModel& pole = cartpole->links()[static_cast<std::size_t>(cartpole->link_index("pole"))];
  EXPECT_EQ(pole.visuals[0].geometry.type, GeometryType::kCapsule);
  EXPECT_EQ(pole.collisions[0].geometry.type, GeometryType::kCapsule);
  EXPECT_DOUBLE_EQ(pole.visuals[0].geometry.length_m, 1.0);
  EXPECT_TRUE(pole.visuals[0].material.has_rgba);
  EXPECT_NEAR(pole.visuals[0].material.rgba.x(), 0.95, 1e-6);  // urdfdom keeps colours as float
  const JointModel& slider =
      cartpole->joints()[static_cast<std::size_t>(cartpole->joint_index("slider"))];
  EXPECT_EQ(slider.type, JointType::kPrismatic);
  EXPECT_DOUBLE_EQ(slider.lower, -2.0);
  const JointModel& hinge =
      cartpole->joints()[static_cast<std::size_t>(cartpole->joint_index("hinge"))];
  EXPECT_EQ(hinge.type, JointType::kContinuous);
  EXPECT_FALSE(hinge.has_limits);
  EXPECT_EQ(hinge.axis, Eigen::Vector3d(0, 1, 0));
}

TEST(RobotModelTest, DofIndexNumbersMovableJointsAsTheWorldDoes) {
  MeshCache meshes;
  // The finger's two chains hang from one base: urdfdom's tree order is not the file's.
  const auto finger = parse_urdf(asset_path("finger/finger.urdf"), meshes);
  for (const char* name : {"proximal", "distal", "hinge"}) {
    const int dof = finger->dof_index(name);
    ASSERT_GE(dof, 0);
    EXPECT_EQ(finger
                  ->joints()[static_cast<std::size_t>(
                      finger->movable_joints()[static_cast<std::size_t>(dof)])]
                  .name,
              name);
  }
  // A fixed joint before the movable one, so that the joint's index is not its degree of
  // freedom's.
  const auto mounted_path =
      std::filesystem::temp_directory_path() / "pixelgym_robot_model_mounted.urdf";
  std::ofstream(mounted_path)
      << "<robot name=\"mounted\"><link name=\"base\"/><link name=\"mount\"/>"
         "<link name=\"bar\"><inertial><mass value=\"1\"/>"
         "<inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link>"
         "<joint name=\"mount_joint\" type=\"fixed\"><parent link=\"base\"/>"
         "<child link=\"mount\"/></joint>"
         "<joint name=\"hinge\" type=\"continuous\"><parent link=\"mount\"/>"
         "<child link=\"bar\"/><axis xyz=\"0 1 0\"/></joint></robot>";
  const auto mounted = parse_urdf(mounted_path.string(), meshes);
  ASSERT_EQ(mounted->joint_index("hinge"), 1);
  EXPECT_EQ(mounted->dof_index("hinge"), 0);

  const auto arm = parse_urdf(asset_path("arm/arm.urdf"), meshes);
  std::string fixed;
  for (const JointModel& joint : arm->joints()) {
    if (joint.type == JointType::kFixed) fixed = joint.name;
  }
  ASSERT_FALSE(fixed.empty());
  EXPECT_THAT([&] { arm->dof_index(fixed); },
              ThrowsMessage<std::out_of_range>(HasSubstr("is fixed, not a degree of freedom")));
  EXPECT_THAT([&] { arm->dof_index("no_such_joint"); },
              ThrowsMessage<std::out_of_range>(HasSubstr("has no joint \"no_such_joint\"")));
}

struct BadCase {
  std::string file;
  std::string problem;
  friend void PrintTo(const BadCase& c, std::ostream* out) { *out << c.file; }
};

class BadUrdfTest : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadUrdfTest, IsRefusedNamingFileAndProblem) {
  MeshCache meshes;
  try {
    parse_urdf(data(GetParam().file), meshes);
    FAIL() << GetParam().file << " was accepted";
  } catch (const UrdfError& error) {
    EXPECT_THAT(error.what(), HasSubstr(GetParam().file));
    EXPECT_THAT(error.what(), HasSubstr(GetParam().problem));
  }
}

INSTANTIATE_TEST_SUITE_P(
    EveryBadFile, BadUrdfTest,
    ::testing::Values(BadCase{"malformed_xml.urdf", "malformed XML at line"},
                      BadCase{"no_links.urdf", "has no links"},
                      BadCase{"two_roots.urdf", "2 root links (\"a\" and \"b\")"},
                      BadCase{"joint_cycle.urdf", "cycle"},
                      BadCase{"detached_cycle.urdf", "cannot be reached from the root"},
                      BadCase{"two_parents.urdf", "child of two joints"},
                      BadCase{"unknown_link.urdf", "\"ghost\", which does not exist"},
                      BadCase{"zero_mass.urdf", "has mass 0 kg"},
                      BadCase{"negative_mass.urdf", "has mass -2 kg"},
                      BadCase{"bad_inertia.urdf", "not positive definite"},
                      BadCase{"reversed_limits.urdf", "lower limit 1.5 > upper limit -1.5"},
                      BadCase{"planar_joint.urdf", "type planar, which pixelgym does not support"},
                      BadCase{"floating_joint.urdf", "type floating"},
                      BadCase{"missing_mesh.urdf",
                              "cannot resolve \"../meshes/does_not_exist.obj\": no file"},
                      BadCase{"unsupported_mesh_format.urdf", "unsupported format \".xyz\""},
                      BadCase{"mesh_without_triangles.urdf", "has no triangles"},
                      BadCase{"unreadable_mesh.urdf", "garbage.stl: cannot be read"},
                      BadCase{"unresolvable_package.urdf", "cannot resolve \"package://"},
                      BadCase{"does_not_exist.urdf", "cannot be read"},
                      BadCase{"nan_box_size.urdf",
                              "link \"base\" visual 0 <box size=\"nan 0.1 0.1\">: expected 3 "
                              "finite numbers > 0"},
                      BadCase{"negative_root_mass.urdf", "link \"base\" has mass -3 kg"},
                      BadCase{"infinite_origin.urdf",
                              "joint \"j1\" <origin xyz=\"0 inf 0.1\">: expected 3 finite numbers"},
                      BadCase{"negative_radius.urdf",
                              "<cylinder radius=\"-0.1\">: expected a finite number > 0"}),
    [](const ::testing::TestParamInfo<BadCase>& param_info) {
      return std::filesystem::path(param_info.param.file).stem().string();
    });

TEST(RobotModelTest, EveryBadFileHasACase) {
  int count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(data(""))) {
    if (entry.path().extension() == ".urdf" && entry.path().filename() != "minimal_valid.urdf")
      ++count;
  }
  EXPECT_EQ(count, 22);
}

// A file of `text` in the test's temporary folder.
std::string write_temporary(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("pixelgym_robot_model_" + name);
  std::ofstream(path) << text;
  return path.string();
}

// A text of `count` copies of `piece`.
std::string repeat(const std::string& piece, int count) {
  std::string text;
  for (int i = 0; i < count; ++i) text += piece;
  return text;
}

// Refused as nested too deep; each of these overflowed the stack (a segfault) before.
void expect_too_deep(const std::string& name, const std::string& text) {
  const std::string path = write_temporary(name, text);
  MeshCache meshes;
  try {
    parse_urdf(path, meshes);
    FAIL() << name << " was accepted";
  } catch (const UrdfError& error) {
    EXPECT_THAT(error.what(), HasSubstr("URDF " + path +
                                        ": elements nested more than 100 deep; "
                                        "a URDF nests at most 100"));
  }
}

TEST(RobotModelTest, DeeplyNestedElementsAreRefusedBeforeParsing) {
  // 50,000 nested elements overflowed tinyxml's recursion (a segfault of pixelgym inspect).
  const std::string robot = "<robot name=\"deep\"><link name=\"base\"/>";
  expect_too_deep("deep.urdf",
                  robot + repeat("<a x=\"<b>\">", 50000) + repeat("</a>", 50000) + "</robot>");
  // Comments, CDATA, self-closing tags and quoted '>' do not count as nesting.
  std::string flat = "<robot name=\"flat\"><!-- <a><a><a> --><link name=\"base\" n=\">\"/>";
  for (int i = 0; i < 200; ++i) flat += "<a/><![CDATA[<b><b>]]><?pi <c>?>";
  flat += "</robot>";
  MeshCache meshes;
  EXPECT_EQ(parse_urdf(write_temporary("flat.urdf", flat), meshes)->links().size(), 1U);
  // 100 deep (the robot and 99 inside it) is allowed.
  const std::string at_limit = robot + repeat("<a>", 99) + repeat("</a>", 99) + "</robot>";
  EXPECT_EQ(parse_urdf(write_temporary("at_limit.urdf", at_limit), meshes)->links().size(), 1U);
  expect_too_deep("past_limit.urdf", robot + repeat("<a>", 100) + repeat("</a>", 100) + "</robot>");
}

TEST(RobotModelTest, NestingHiddenFromASimpleReaderIsCountedAsTinyXmlParsesIt) {
  // Issue 42: '<' then a byte that starts no name is an unknown node to TinyXML, which ends at the
  // first '>' even inside quotes; the old count read a quoted value over the whole nest.
  const std::string robot = "<robot name=\"r\"><link name=\"a\"/>";
  const std::string nest = repeat("<x>", 50000) + repeat("</x>", 50000);
  expect_too_deep("unknown_node.urdf", robot + "<1 \"> " + nest + " \"></robot>");
  // A character reference runs to the next ';' after digits: "&#<!--#1;" hides a comment opener.
  expect_too_deep("reference.urdf", robot + "&#<!--#1;" + nest + "--></robot>");
  // After a UTF-8 declaration, a lead byte swallows the quote after it.
  expect_too_deep("utf8_lead_byte.urdf", "<?xml version=\"1.0\" encoding=\"UTF-8\"?>" + robot +
                                             "<y z=\"\xe0\" \">" + nest + "\"/></robot>");
  // A declaration's values are printed back unescaped into the XML urdfdom parses: the file nests
  // 2 deep, the text urdfdom is given 50,002.
  expect_too_deep("declaration.urdf", "<?xml version=\"&quot;&gt;" + repeat("&lt;x&gt;", 50000) +
                                          "\"?>" + robot + "</robot>");
}

TEST(RobotModelTest, OnlyRegularFilesOfBoundedSizeAreRead) {
  // A FIFO blocked the read forever and /dev/zero filled memory; each is now refused at once. An
  // alarm ends the test (and fails it) should the read block.
  const auto folder = std::filesystem::temp_directory_path() / "pixelgym_robot_model_files";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const auto refusal = [](const std::string& path) {
    MeshCache meshes;
    ::alarm(20);
    try {
      parse_urdf(path, meshes);
      ::alarm(0);
      return std::string("accepted");
    } catch (const UrdfError& error) {
      ::alarm(0);
      return std::string(error.what());
    }
  };
  const std::string fifo = (folder / "fifo.urdf").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(refusal(fifo), "URDF " + fifo + ": is a FIFO, not a regular file");
  const std::string zero = (folder / "zero.urdf").string();
  std::filesystem::create_symlink("/dev/zero", zero);
  EXPECT_EQ(refusal(zero), "URDF " + zero +
                               ": is a symbolic link to /dev/zero, which is a character device, "
                               "not a regular file");
  EXPECT_EQ(refusal("/dev/urandom"),
            "URDF /dev/urandom: is a character device, not a regular file");
  EXPECT_EQ(refusal(folder.string()),
            "URDF " + folder.string() + ": is a folder, not a regular file");
  // 3 GB, sparse: nothing is written, and nothing may be read.
  const std::string huge = (folder / "huge.urdf").string();
  std::ofstream(huge).close();
  std::filesystem::resize_file(huge, 3'000'000'000ULL);
  EXPECT_EQ(refusal(huge), "URDF " + huge +
                               ": is 2.8 GiB (3000000000 bytes); a URDF file may be at "
                               "most 32 MiB (33554432 bytes)");
  // Both sides of the bound: a valid URDF padded with a comment to exactly kMaxUrdfBytes is read.
  const std::string minimal = "<robot name=\"r\"><link name=\"a\"/></robot>";
  const std::string at_cap = (folder / "at_cap.urdf").string();
  std::ofstream(at_cap) << minimal << "<!--" << std::string(kMaxUrdfBytes - minimal.size() - 7, ' ')
                        << "-->";
  ASSERT_EQ(std::filesystem::file_size(at_cap), kMaxUrdfBytes);
  EXPECT_EQ(refusal(at_cap), "accepted");
  std::ofstream(at_cap, std::ios::app) << " ";
  EXPECT_EQ(refusal(at_cap), "URDF " + at_cap +
                                 ": is 32.0 MiB (33554433 bytes); a URDF file may be at "
                                 "most 32 MiB (33554432 bytes)");
  std::filesystem::remove_all(folder);
}

TEST(RobotModelTest, StiffnessIsReadFromDynamicsAndANegativeOneIsRefused) {
  const auto urdf = [](const std::string& dynamics) {
    const std::string inertial =
        "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" "
        "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
    return "<robot name=\"r\"><link name=\"a\">" + inertial + "</link><link name=\"b\">" +
           inertial +
           "</link><joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child "
           "link=\"b\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
           "velocity=\"1\"/>" +
           dynamics + "</joint></robot>";
  };
  MeshCache meshes;
  const auto joint = [&](const std::string& name, const std::string& dynamics) {
    return parse_urdf(write_temporary(name, urdf(dynamics)), meshes)->joints()[0];
  };
  EXPECT_EQ(joint("no_dynamics.urdf", "").stiffness, 0.0);
  EXPECT_EQ(joint("damping_only.urdf", "<dynamics damping=\"2\"/>").stiffness, 0.0);
  const JointModel spring = joint("spring.urdf", "<dynamics damping=\"2\" stiffness=\"240\"/>");
  EXPECT_EQ(spring.stiffness, 240.0);
  EXPECT_EQ(spring.damping, 2.0);
  try {
    joint("negative_spring.urdf", "<dynamics stiffness=\"-5\"/>");
    ADD_FAILURE() << "a negative stiffness was accepted";
  } catch (const UrdfError& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("joint \"j\" has a negative stiffness"));
  }
  try {
    joint("nan_spring.urdf", "<dynamics stiffness=\"nan\"/>");
    ADD_FAILURE() << "a stiffness of nan was accepted";
  } catch (const UrdfError& error) {
    EXPECT_THAT(error.what(), ::testing::HasSubstr("stiffness"));
  }
}

TEST(RobotModelTest, HugeFiniteLimitsAndOriginsAreRefusedNamingTheRange) {
  // A limit of 1e300 made UrdfReach-v0's reset diverge ("joint_pos[0] is inf") and an origin of
  // 1e200 failed in the camera ("the pose is not finite"), neither naming the URDF.
  const auto urdf = [](const std::string& joint_origin, const std::string& limit) {
    const std::string inertial =
        "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" "
        "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
    return "<robot name=\"r\"><link name=\"a\">" + inertial + "</link><link name=\"b\">" +
           inertial +
           "</link><joint name=\"j\" type=\"prismatic\"><parent link=\"a\"/><child "
           "link=\"b\"/><axis xyz=\"1 0 0\"/>" +
           joint_origin + limit + "<dynamics damping=\"0.1\"/></joint></robot>";
  };
  const std::string limit = "<limit lower=\"-1\" upper=\"1\" effort=\"10\" velocity=\"1\"/>";
  MeshCache meshes;
  // At the bounds: accepted.
  EXPECT_EQ(parse_urdf(write_temporary("at_bounds.urdf",
                                       urdf("<origin xyz=\"10000 -10000 0\" rpy=\"0 -10000 0\"/>",
                                            "<limit lower=\"-10000\" upper=\"10000\" "
                                            "effort=\"1e9\" velocity=\"1e6\"/>")),
                       meshes)
                ->joints()[0]
                .upper,
            1e4);
  struct Case {
    std::string origin;
    std::string limit;
    std::string problem;
  };
  const std::vector<Case> cases = {
      {"", "<limit lower=\"-1\" upper=\"1e300\" effort=\"10\" velocity=\"1\"/>",
       "joint \"j\" <limit upper=\"1e300\">: 1e300 is outside [-10000, 10000] rad or m"},
      {"", "<limit lower=\"-10000.1\" upper=\"1\" effort=\"10\" velocity=\"1\"/>",
       "<limit lower=\"-10000.1\">: -10000.1 is outside [-10000, 10000] rad or m"},
      {"<origin xyz=\"0 0 1e200\"/>", limit,
       "joint \"j\" <origin xyz=\"0 0 1e200\">: 1e200 is outside [-10000, 10000] m"},
      {"<origin rpy=\"0 0 -2e4\"/>", limit, "<origin rpy=\"0 0 -2e4\">: -2e4 is outside"},
      {"", "<limit lower=\"-1\" upper=\"1\" effort=\"1.1e9\" velocity=\"1\"/>",
       "<limit effort=\"1.1e9\">: 1.1e9 is outside [-1e+09, 1e+09] N m or N"},
      {"", "<limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1e300\"/>",
       "<limit velocity=\"1e300\">: 1e300 is outside [-1e+06, 1e+06] rad/s or m/s"},
  };
  for (const Case& c : cases) {
    const std::string path = write_temporary("huge.urdf", urdf(c.origin, c.limit));
    try {
      parse_urdf(path, meshes);
      FAIL() << c.problem << ": accepted";
    } catch (const UrdfError& error) {
      EXPECT_THAT(error.what(), HasSubstr("URDF " + path + ": "));
      EXPECT_THAT(error.what(), HasSubstr(c.problem));
    }
  }
}

std::string chain_urdf(std::size_t links) {
  std::string text = "<robot name=\"chain\">";
  const std::string inertial =
      "<inertial><mass value=\"1\"/><inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" "
      "ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>";
  for (std::size_t i = 0; i < links; ++i) {
    text += "<link name=\"l" + std::to_string(i) + "\">" + inertial + "</link>";
  }
  for (std::size_t i = 1; i < links; ++i) {
    text += "<joint name=\"j" + std::to_string(i) + "\" type=\"revolute\"><parent link=\"l" +
            std::to_string(i - 1) + "\"/><child link=\"l" + std::to_string(i) +
            "\"/><axis xyz=\"0 1 0\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
            "velocity=\"1\"/></joint>";
  }
  return text + "</robot>";
}

TEST(RobotModelTest, RobotsOfMoreThanTheLinkLimitAreRefused) {
  // A chain of 3,000 links took 722 MB in Bullet, one of 10,000 5.7 GB: refused, naming the limit.
  MeshCache meshes;
  EXPECT_EQ(
      parse_urdf(write_temporary("chain512.urdf", chain_urdf(kMaxLinks)), meshes)->links().size(),
      kMaxLinks);
  try {
    parse_urdf(write_temporary("chain3000.urdf", chain_urdf(3000)), meshes);
    FAIL() << "a chain of 3,000 links was accepted";
  } catch (const UrdfError& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("has 3000 links; pixelgym simulates robots of at most 512"));
  }
}

TEST(RobotModelTest, InlineColoursAndTextureFileNames) {
  MeshCache meshes;
  const auto model = parse_urdf(
      std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/inline_material.urdf", meshes);
  const LinkModel& base = model->links()[0];
  ASSERT_EQ(base.visuals.size(), 2U);
  EXPECT_TRUE(base.visuals[0].material.has_rgba);
  EXPECT_TRUE(base.visuals[0].material.rgba.isApprox(Eigen::Vector4d(0.1, 0.2, 0.3, 0.4), 1e-6));
  EXPECT_EQ(base.visuals[0].material.name, "painted");
  EXPECT_TRUE(base.visuals[0].material.texture_path.empty());
  EXPECT_EQ(base.visuals[1].material.texture_path,
            std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/checker.png");
  EXPECT_EQ(base.visuals[0].geometry.box_size_m, Eigen::Vector3d(0.1, 0.2, 0.3));
}

TEST(RobotModelTest, ResolvesRelativeFileAndPackageUris) {
  const std::string urdf = asset_path("arm/arm.urdf");
  const std::string link1 = asset_path("arm/meshes/link1.obj");
  EXPECT_EQ(resolve_uri("meshes/link1.obj", urdf), link1);
  EXPECT_EQ(resolve_uri("file://" + link1, urdf), link1);
  EXPECT_EQ(resolve_uri(link1, urdf), link1);
  EXPECT_EQ(resolve_uri("package://arm/meshes/link1.obj", urdf), link1);
  EXPECT_EQ(resolve_uri("package://anything/meshes/link1.obj", urdf), link1);
  EXPECT_THROW(resolve_uri("package://arm/meshes/nothing.obj", urdf), UrdfError);
  // A relative path that is nowhere near the URDF is found in pixelgym's assets/.
  const std::string elsewhere =
      (std::filesystem::temp_directory_path() / "x" / "robot.urdf").string();
  EXPECT_EQ(resolve_uri("arm/meshes/link1.obj", elsewhere), link1);
}

TEST(RobotModelTest, RelativeMeshUrisResolveAgainstTheUrdfsParentFolders) {
  // tests/data/urdf_good/nested/relative_to_a_parent.urdf names "meshes/two_tone.obj", which is
  // in tests/data/meshes: two folders up.
  MeshCache meshes;
  const auto model = parse_urdf(
      std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/nested/relative_to_a_parent.urdf",
      meshes);
  ASSERT_EQ(model->links()[0].visuals.size(), 1U);
  EXPECT_EQ(model->links()[0].visuals[0].geometry.mesh->path,
            std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/meshes/two_tone.obj");
}

// A folder under the system's temporary folder, removed with everything in it at the end.
class TemporaryFolder {
 public:
  explicit TemporaryFolder(const std::string& name)
      : path_(std::filesystem::temp_directory_path() /
              (name + "_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
               "_" + std::to_string(reinterpret_cast<std::uintptr_t>(this)))) {
    std::filesystem::create_directories(path_);
  }
  ~TemporaryFolder() { std::filesystem::remove_all(path_); }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

void write_file(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

TEST(RobotModelTest, RelativeMeshUrisResolveThroughPixelgymAssetPath) {
  TemporaryFolder robot("pixelgym_robot");
  TemporaryFolder library("pixelgym_asset_library");
  const std::string urdf = (robot.path() / "robot.urdf").string();
  write_file(urdf,
             "<robot name=\"r\"><link name=\"base\"><visual><geometry>"
             "<mesh filename=\"shared/triangle.obj\"/></geometry></visual></link></robot>");
  const std::filesystem::path mesh = library.path() / "shared" / "triangle.obj";
  write_file(mesh, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");

  const char* previous = std::getenv("PIXELGYM_ASSET_PATH");
  const std::string saved = previous == nullptr ? "" : previous;
  // Not found without the library on the path; the message says what and where.
  ::unsetenv("PIXELGYM_ASSET_PATH");
  try {
    MeshCache meshes;
    parse_urdf(urdf, meshes);
    ADD_FAILURE() << "shared/triangle.obj was found without PIXELGYM_ASSET_PATH";
  } catch (const UrdfError& error) {
    EXPECT_THAT(error.what(), HasSubstr("cannot resolve \"shared/triangle.obj\": no file"));
    EXPECT_THAT(error.what(), HasSubstr(robot.path().string() + " (the URDF's folder)"));
    EXPECT_THAT(error.what(), HasSubstr("PIXELGYM_ASSET_PATH"));
  }
  // Found in the second folder of PIXELGYM_ASSET_PATH (the first does not have it).
  ::setenv("PIXELGYM_ASSET_PATH", ("/nonexistent/folder:" + library.path().string()).c_str(), 1);
  MeshCache meshes;
  const auto model = parse_urdf(urdf, meshes);
  EXPECT_EQ(model->links()[0].visuals[0].geometry.mesh->path, mesh.lexically_normal().string());
  // A file beside the URDF comes first.
  write_file(robot.path() / "shared" / "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(resolve_uri("shared/triangle.obj", urdf),
            (robot.path() / "shared" / "triangle.obj").lexically_normal().string());
  if (previous == nullptr) {
    ::unsetenv("PIXELGYM_ASSET_PATH");
  } else {
    ::setenv("PIXELGYM_ASSET_PATH", saved.c_str(), 1);
  }
}

TEST(RobotModelTest, UrdfColoursAreReadBesideTheMeshsOwnColours) {
  // tests/data/urdf_good/coloured_mesh.urdf: one two-colour mesh, with an inline colour, a named
  // colour defined at the robot level, and no colour.
  MeshCache meshes;
  const auto model = parse_urdf(
      std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf_good/coloured_mesh.urdf", meshes);
  const std::vector<VisualElement>& visuals = model->links()[0].visuals;
  ASSERT_EQ(visuals.size(), 3U);
  EXPECT_TRUE(visuals[0].material.has_rgba);
  EXPECT_TRUE(visuals[0].material.rgba.isApprox(Eigen::Vector4d(0.1, 0.7, 0.2, 1.0), 1e-6));
  EXPECT_TRUE(visuals[1].material.has_rgba);
  EXPECT_TRUE(visuals[1].material.rgba.isApprox(Eigen::Vector4d(0.8, 0.1, 0.1, 1.0), 1e-6));
  EXPECT_FALSE(visuals[2].material.has_rgba);
  // The mesh keeps its own colours either way (whether they are drawn is the scene's choice).
  const Mesh& mesh = *visuals[2].geometry.mesh;
  EXPECT_EQ(visuals[0].geometry.mesh.get(), &mesh) << "one file, read once";
  ASSERT_EQ(mesh.parts.size(), 2U);
  EXPECT_TRUE(mesh.parts[0].has_color);
  EXPECT_TRUE(mesh.parts[1].has_color);
  std::vector<Eigen::Vector4f> colours = {mesh.parts[0].rgba, mesh.parts[1].rgba};
  std::sort(colours.begin(), colours.end(),
            [](const Eigen::Vector4f& a, const Eigen::Vector4f& b) { return a.z() > b.z(); });
  EXPECT_TRUE(colours[0].head<3>().isApprox(Eigen::Vector3f(0.1F, 0.2F, 0.9F), 1e-3F));  // top
  EXPECT_TRUE(colours[1].head<3>().isApprox(Eigen::Vector3f(0.9F, 0.8F, 0.1F), 1e-3F));  // sides
}

TEST(ModelCacheTest, ParsesOnceAndReadsEachMeshOnce) {
  ModelCache cache;
  const auto first = cache.load_urdf(asset_path("arm/arm.urdf"));
  for (int i = 0; i < 15; ++i)
    EXPECT_EQ(cache.load_urdf(asset_path("arm/arm.urdf")).get(), first.get());
  EXPECT_EQ(cache.urdfs_parsed(), 1);
  EXPECT_EQ(cache.meshes().files_read(), 16);  // 7 visuals + 7 hulls + pedestal + hand
}

}  // namespace
}  // namespace pixelgym::engine
