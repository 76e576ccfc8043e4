// Re-encodes every colour image of a TUM-layout sequence as JPEG of a given quality, for the
// accuracy panel's re-encoding cell (bench/experiments/accuracy_panel.toml): the same frames,
// other compression artefacts, so a change that only fits one encoding of the clip shows up as a
// loss there.
//   reencode_colour IN_SEQUENCE OUT_SEQUENCE QUALITY
// OUT gets rgb/ (JPEG, file names kept so rgb.txt stays valid) and links to everything else of IN
// (depth/, depth.txt, rgb.txt, groundtruth.txt, ...): nothing but the colour pixels changes.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc != 4) {
    std::cerr << "usage: reencode_colour IN_SEQUENCE OUT_SEQUENCE QUALITY(1-100)\n";
    return 2;
  }
  const fs::path in = argv[1];
  const fs::path out = argv[2];
  int quality = 0;
  try {
    quality = std::stoi(argv[3]);
  } catch (const std::exception&) {
  }
  if (quality < 1 || quality > 100) {
    std::cerr << "error: QUALITY must be an integer in [1, 100], got '" << argv[3] << "'\n";
    return 2;
  }
  if (!fs::is_directory(in / "rgb")) {
    std::cerr << "error: '" << (in / "rgb").string() << "' is not a folder\n";
    return 2;
  }
  fs::create_directories(out / "rgb");
  for (const fs::directory_entry& entry : fs::directory_iterator(in)) {
    const fs::path target = out / entry.path().filename();
    if (entry.path().filename() == "rgb" || fs::exists(fs::symlink_status(target))) continue;
    fs::create_symlink(fs::absolute(entry.path()), target);
  }
  const std::vector<int> params = {cv::IMWRITE_JPEG_QUALITY, quality};
  size_t written = 0;
  for (const fs::directory_entry& entry : fs::directory_iterator(in / "rgb")) {
    const cv::Mat image = cv::imread(entry.path().string(), cv::IMREAD_UNCHANGED);
    if (image.empty()) {
      std::cerr << "error: '" << entry.path().string() << "': cannot read the image\n";
      return 2;
    }
    // The name is kept (a .png keeps its name but holds JPEG bytes: OpenCV reads by content).
    std::vector<unsigned char> bytes;
    cv::imencode(".jpg", image, bytes, params);
    const fs::path target = out / "rgb" / entry.path().filename();
    std::ofstream file(target, std::ios::binary);
    file.write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
    if (!file) {
      std::cerr << "error: '" << target.string() << "': cannot write\n";
      return 2;
    }
    ++written;
  }
  std::cout << written << " colour images re-encoded at JPEG quality " << quality << " into "
            << out.string() << "\n";
  return 0;
}
