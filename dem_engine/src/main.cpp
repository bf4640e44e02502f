// dem_engine: runs LIGGGHTS 3.8-syntax granular decks.
#include <omp.h>

#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "contact/contact_model.h"
#include "core/simulation.h"
#include "deck/errors.h"

namespace {
void usage() {
  std::cerr << "usage: dem_engine -in DECK [-var NAME VALUE ...] [-log FILE|none]"
               " [-echo none|screen] [-noprogress]\n"
               "threads: OMP_NUM_THREADS\n";
}
}  // namespace

int main(int argc, char** argv) {
  std::string deck;
  dem::EngineOptions options;
  std::vector<std::pair<std::string, std::vector<std::string>>> vars;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto need = [&](int k) {
      if (i + k >= argc) {
        std::cerr << "ERROR: " << a << " needs " << k << " argument(s)\n";
        usage();
        std::exit(2);
      }
    };
    if (a == "-in" || a == "-i") {
      need(1);
      deck = argv[++i];
    } else if (a == "-log") {
      need(1);
      options.log_file = argv[++i];
    } else if (a == "-echo") {
      need(1);
      const std::string e = argv[++i];
      if (e != "none" && e != "screen") {
        std::cerr << "ERROR: -echo takes none or screen\n";
        return 2;
      }
      options.echo_screen = e == "screen";
    } else if (a == "-var" || a == "-v") {
      need(2);
      std::pair<std::string, std::vector<std::string>> v{argv[++i], {}};
      while (i + 1 < argc && argv[i + 1][0] != '-') v.second.push_back(argv[++i]);
      vars.push_back(v);
    } else if (a == "-noprogress") {
      options.progress = false;
    } else if (a == "-h" || a == "-help") {
      usage();
      return 0;
    } else {
      std::cerr << "ERROR: unknown option '" << a << "'\n";
      usage();
      return 2;
    }
  }
  if (deck.empty()) {
    usage();
    return 2;
  }
  try {
    dem::Simulation sim(options);
    sim.message("dem_engine: " + std::to_string(omp_get_max_threads()) +
                " OpenMP threads, contact law on packs of " +
                std::to_string(dem::contact_pack_lanes()));
    sim.run_deck(deck, vars);
  } catch (const dem::DeckError& e) {
    std::cerr << "ERROR: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "ERROR: " << deck << ": " << e.what() << '\n';
    return 1;
  }
  return 0;
}
