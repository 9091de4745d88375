// Drives OpenSees' own uniaxial materials (compiled from OpenSees' source outside the
// project by make_reference.sh) along the uniaxial bench's strain path and prints
// t, strain, stress with 17 significant digits. Part of hysteron, not of OpenSees.
//
// Usage: driver MATERIAL AMPLITUDE DRIFT END STEPS EVERY P1 P2 ...
//   MATERIAL  BoucWen | BoucWenOriginal | BWBN
//   the strain at t_k = END k / STEPS is AMPLITUDE t / END sin(2 pi t) + DRIFT t / END,
//   evaluated as the bench evaluates `Strain = A*t/END*sin(2*pi*t) + B*t/END`;
//   every step is integrated (setTrialStrain, then commitState), every EVERY-th is printed;
//   P1 ... are the constructor's numbers after the tag, in OpenSees' order, tolerance and
//   iteration limit included.
#include <BWBN.h>
#include <BoucWenMaterial.h>
#include <BoucWenOriginal.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace
{
  std::unique_ptr<UniaxialMaterial>
  make_material(const std::string &name, const std::vector<double> &p)
  {
    const auto n = [&](const std::size_t count) {
      if (p.size() != count)
        {
          std::fprintf(stderr, "%s takes %zu numbers, got %zu\n", name.c_str(), count, p.size());
          std::exit(2);
        }
    };
    if (name == "BoucWen")
      {
        n(11); // alpha ko n gamma beta Ao deltaA deltaNu deltaEta tolerance maxNumIter
        return std::make_unique<BoucWenMaterial>(
          1, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], int(p[10]));
      }
    if (name == "BoucWenOriginal")
      {
        n(10); // E fy alphaL alphaNL mu eta beta gamma tol maxIter
        return std::make_unique<BoucWenOriginal>(
          1, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], int(p[9]));
      }
    if (name == "BWBN")
      {
        n(14); // alpha ko n gamma beta Ao q zetas p Shi deltaShi lamda tolerance maxNumIter
        return std::make_unique<BWBN>(1, p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8],
                                      p[9], p[10], p[11], p[12], int(p[13]));
      }
    std::fprintf(stderr, "unknown material %s\n", name.c_str());
    std::exit(2);
  }
} // namespace

int
main(int argc, char **argv)
{
  if (argc < 7)
    {
      std::fprintf(stderr, "usage: %s MATERIAL AMPLITUDE DRIFT END STEPS EVERY P1 P2 ...\n", argv[0]);
      return 2;
    }
  const std::string   name      = argv[1];
  const double        amplitude = std::atof(argv[2]), drift = std::atof(argv[3]);
  const double        end       = std::atof(argv[4]);
  const unsigned int  steps = std::atoi(argv[5]), every = std::atoi(argv[6]);
  std::vector<double> p;
  for (int i = 7; i < argc; ++i)
    p.push_back(std::atof(argv[i]));
  const auto   material = make_material(name, p);
  const double pi       = 3.141592653589793238462643;

  std::printf("t,strain,stress\n");
  for (unsigned int k = 0; k <= steps; ++k)
    {
      // As the bench: t_k = End time k / Steps, the same expression in the same order.
      const double t      = end * k / steps;
      const double strain = amplitude * t / end * std::sin(2 * pi * t) + drift * t / end;
      material->setTrialStrain(strain, 0.0);
      material->commitState();
      if (k % every == 0 || k == steps)
        std::printf("%.17g,%.17g,%.17g\n", t, strain, material->getStress());
    }
  return 0;
}
