//! Exponential moving average of the weights: the shipped network is the average of the
//! recent iterates, which samples far better than the last iterate of a noisy optimiser.

use infiniterra_terrain::model::burn;

use burn::module::{Module, ModuleMapper, ModuleVisitor, Param};
use burn::tensor::Tensor;

/// Returns `beta·ema + (1 − beta)·current`, parameter by parameter. Both networks must have
/// the same architecture (parameters are matched by their order in the module tree); the
/// result stays on `ema`'s device and carries no gradient graph.
pub fn blend<M: Module>(ema: M, current: &M, beta: f32) -> M {
    struct Collect(Vec<Tensor<1>>);
    impl ModuleVisitor for Collect {
        fn visit_float<const D: usize>(&mut self, param: &Param<Tensor<D>>) {
            let t = param.val().inner();
            let n = t.dims().iter().product::<usize>();
            self.0.push(t.reshape([n]));
        }
    }
    struct Blend {
        values: std::vec::IntoIter<Tensor<1>>,
        beta: f32,
    }
    impl ModuleMapper for Blend {
        fn map_float<const D: usize>(&mut self, param: Param<Tensor<D>>) -> Param<Tensor<D>> {
            let current = self.values.next().expect("EMA and network have the same parameters");
            let beta = self.beta;
            param.map(|e| {
                let dims = e.dims();
                let current = current.to_device(&e.device()).reshape(dims);
                e.mul_scalar(beta) + current.mul_scalar(1.0 - beta)
            })
        }
    }
    let mut collect = Collect(Vec::new());
    current.visit(&mut collect);
    ema.map(&mut Blend { values: collect.0.into_iter(), beta })
}
