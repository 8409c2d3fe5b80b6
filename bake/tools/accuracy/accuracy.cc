// `skybake accuracy`: the studies of study.h in turn, one Vulkan context for
// all, their markdown joined into accuracy_results.md. A new study is a file
// of its own (study.h says how) and one line here.
#include "skybake/tools/accuracy.h"

#include <filesystem>

#include "skybake/output/exr_io.h"
#include "study.h"

namespace skybake {

std::string RunAccuracyStudy(const AccuracyStudyOptions& options) {
  std::filesystem::create_directories(options.out_dir);
  VulkanOptions vulkan_options;
  VulkanContext vulkan(vulkan_options);
  StudyContext context{options, vulkan, {}};

  std::string md;
  // --study spectral or --only spectral: the spectral study alone (its own
  // spectral_results.md); --only kider-spectral: Kider 2014 by wavelength alone.
  if (options.study == "spectral" || options.only == "spectral") return RunSpectralStudy(context);
  if (options.only == "kider-spectral") return RunKiderSpectralStudy(context);  // kider2014_spectral.csv
  if (options.study == "twilight") {                                            // twilight.csv, twilight_results.md
    const std::string md = RunTwilightStudy(context);
    WriteFileAtomically(options.out_dir + "/twilight_results.md", md);
    return md;
  }
  if (options.study != "clouds") {
    md += RunIntegratorStudy(context);     // accuracy.csv, accuracy.png
    md += RunKiderStudy(context);          // kider2014.csv
    md += RunKiderSpectralStudy(context);  // kider2014_spectral.csv
  }
  if (options.study == "all") md += RunTwilightStudy(context);  // twilight.csv
  if (options.study == "all" && options.only.empty())
    md += RunSpectralStudy(context);                                // spectral.csv, spectral_twilight_*.png
  if (options.study != "sky") md += RunCloudQualityStudy(context);  // cloud_study.csv, cloud_study.png
  for (const std::string& note : context.notes) md += "\n" + note + "\n";
  WriteFileAtomically(options.out_dir + "/accuracy_results.md", md);
  return md;
}

}  // namespace skybake
