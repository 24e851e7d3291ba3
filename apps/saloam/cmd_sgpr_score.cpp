// `saloam sgpr-score`: SGPR similarity of semantic graphs (JSON).

#include <iostream>

#include <fmt/format.h>

#include "command.hpp"
#include "saloam/place/graph_json.hpp"
#include "saloam/place/sgpr_network.hpp"

namespace saloam::cli {
namespace {

struct ScoreArgs {
  ConfigOptions config;
  std::string model;
  std::vector<std::string> graphs;
};

int run_sgpr_score(const ScoreArgs& args) {
  const SaloamConfig config = args.config.resolve();
  const SgprNetwork network = SgprNetwork::load(sgpr_model_path(args.model, config));
  const SemanticGraph query = read_graph_json(args.graphs.front());
  const SgprEmbedding query_embedding = network.embed(query);
  for (std::size_t i = 1; i < args.graphs.size(); ++i) {
    const SemanticGraph candidate = read_graph_json(args.graphs[i]);
    SgprPairActivations result;
    (void)network.score(query_embedding, network.embed(candidate), &result);
    std::cout << fmt::format("{} {} score {:.6f} logit {:.4f}\n", args.graphs.front(), args.graphs[i], result.score,
                             result.logit);
  }
  return 0;
}

const CommandRegistration kRegistration{Command{
    "sgpr-score", "SGPR similarity of the first graph with each further graph (order matters)", 41,
    [](CLI::App& app) {
      auto args = std::make_shared<ScoreArgs>();
      args->config.add_to(app);
      app.add_option("--model", args->model,
                     "SGPR weights (.sgw); default: config loop.sgpr_model, else the shipped models/sgpr/saloam.sgw");
      app.add_option("graphs", args->graphs, "Graph files (.json): the first is scored against each of the others")
          ->required()
          ->expected(2, -1);
      return [args] { return run_sgpr_score(*args); };
    }}};

}  // namespace
}  // namespace saloam::cli
